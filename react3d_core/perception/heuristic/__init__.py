"""Weight-free heuristic perception: openable fronts found geometrically on the scan mesh.

Two sources of fronts: planar facets of the mesh (seams between fronts separate them) that are
vertical, rectangular, door/drawer-sized and carry a handle (fronts.py), and — where the mesh has no
seams, as in real scans — the colour frames: each large vertical plane is fused into an orthophoto
from all views that see it and split at the seams and between the handles it shows
(image_fronts.py). The joint comes from shape and handle; two equally tall fronts side by side a track
apart (one a few cm in front of the other) are a pair of sliding doors (sliding.py). All five perception calls read per-frame
renders of these fronts (docs/perception.md states the limits).
"""

from __future__ import annotations

from ...config import PerceptionConfig
from ...data.frames import SceneInput
from ..interfaces import Perception
from ..versions import HEURISTIC_VERSION
from .backend import (HeuristicArticulation, HeuristicModel, HeuristicPointSegmenter, HeuristicSegmenter,
                      HeuristicTagger, KeepOpenable)

STAGE_VERSION = HEURISTIC_VERSION  # history in react3d_core/perception/versions.py


def make_heuristic(scene: SceneInput, config: PerceptionConfig) -> Perception:
    """Build the heuristic backend for ``scene`` (facets and fronts are computed once here)."""
    model = HeuristicModel(scene, config.heuristic)
    return Perception(name="heuristic", tagger=HeuristicTagger(model), tag_filter=KeepOpenable(),
                      segmenter=HeuristicSegmenter(model), point_segmenter=HeuristicPointSegmenter(model),
                      articulation=HeuristicArticulation(model), version=STAGE_VERSION)


__all__ = ["STAGE_VERSION", "HeuristicModel", "make_heuristic"]
