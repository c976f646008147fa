"""Weight-free heuristic perception: openable fronts found geometrically on the scan mesh.

Planar facets (faces joined where normals agree; seams between fronts separate them) that are
vertical, rectangular, door/drawer-sized, seen by the cameras and carry a handle in front of them
(or sit beside another such front) are openable fronts; the joint comes from shape and handle. All
five perception calls read per-frame renders of these fronts. Named a heuristic: it needs the seams
between fronts to exist in the mesh and misses handle-less lone fronts (docs/perception.md).
"""

from __future__ import annotations

from ...config import PerceptionConfig
from ...data.frames import SceneInput
from ..interfaces import Perception
from .backend import (HeuristicArticulation, HeuristicModel, HeuristicPointSegmenter, HeuristicSegmenter,
                      HeuristicTagger, KeepOpenable)
from .fronts import FrontRules

STAGE_VERSION = "2"  # 2: frame-and-panel fronts, rims, drawer_max_h 0.45


def make_heuristic(scene: SceneInput, config: PerceptionConfig) -> Perception:
    """Build the heuristic backend for ``scene`` (facets and fronts are computed once here)."""
    model = HeuristicModel(scene, FrontRules())
    return Perception(name="heuristic", tagger=HeuristicTagger(model), tag_filter=KeepOpenable(),
                      segmenter=HeuristicSegmenter(model), point_segmenter=HeuristicPointSegmenter(model),
                      articulation=HeuristicArticulation(model), version=STAGE_VERSION)


__all__ = ["STAGE_VERSION", "HeuristicModel", "make_heuristic"]
