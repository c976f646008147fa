"""A ``scene-synthesizer`` procedural kitchen (real cabinets, appliances, 20-30 joints) as a scan.

The kitchen is exported to URDF in a temporary folder and read back by :mod:`.from_urdf`, so both
sources share one code path; dishwasher baskets (internal sliding parts, not fronts) are skipped.

The library sometimes places several wall cabinets on the same stretch of wall (seed 210: five wall
cabinets in one 1 m slot, 13 of 39 joints). Their doors occupy the same place, z-fight in the renders
and can never be found, so objects that overlap an earlier one are dropped before the export
(:func:`overlapping_objects`); their names go to ``synth_meta.json`` (``dropped_objects``).
"""

from __future__ import annotations

import re
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .procedural import SynthLayout

#: an object is dropped when its box shares more than this fraction of the smaller box's volume with an
#: object kept before it ...
OVERLAP_FRACTION = 0.10
#: ... and the shared box is thicker than this on every axis. Measured on seeds 1, 209 and 210: objects
#: that belong together only touch (0 volume: cabinet beside cabinet, countertop on cabinet, refrigerator
#: beside a wall cabinet) or meet at 3 mm x 3 mm corners (wall cabinets round a corner), fraction 0.000;
#: stacked wall cabinets share 1.0 of the smaller box and are 0.41 m thick in common. The thickness
#: guard keeps a thin object (a 3 cm countertop) that sinks a centimetre or two into its cabinet, where
#: the fraction of the thin box alone can exceed 0.10 without anything z-fighting.
OVERLAP_THICKNESS = 0.05


def box_overlap(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Two axis-aligned boxes (2 x 3, min and max rows): the shared volume over the smaller box's volume,
    and the thinnest extent of the shared box (0 where they do not overlap)."""
    ext = np.clip(np.minimum(a[1], b[1]) - np.maximum(a[0], b[0]), 0.0, None)
    smaller = min(float(np.prod(a[1] - a[0])), float(np.prod(b[1] - b[0])))
    frac = float(np.prod(ext)) / smaller if smaller > 0 else 0.0
    return frac, float(ext.min())


def overlapping_objects(boxes: dict[str, np.ndarray], fraction: float = OVERLAP_FRACTION,
                        thickness: float = OVERLAP_THICKNESS) -> dict[str, tuple[str, float]]:
    """Objects to drop, in placement order (``boxes``' order): each that overlaps an object kept before
    it (more than ``fraction`` of the smaller box, and thicker than ``thickness`` m on every axis), with
    the kept object it overlaps most and that fraction. The first placed wins."""
    kept: list[str] = []
    dropped: dict[str, tuple[str, float]] = {}
    for name, box in boxes.items():
        hits = []
        for other in kept:
            frac, thin = box_overlap(box, boxes[other])
            if frac > fraction and thin > thickness:
                hits.append((frac, other))
        if hits:
            frac, other = max(hits, key=lambda h: h[0])  # ties: the earliest placed (max keeps the first)
            dropped[name] = (other, round(frac, 3))
        else:
            kept.append(name)
    return dropped


def _object_boxes(scene) -> dict[str, np.ndarray]:  # noqa: ANN001 - a scene_synthesizer.Scene
    """World axis-aligned box of every object with geometry, in the library's placement order."""
    boxes = {}
    for name in scene.get_object_names():
        try:
            boxes[name] = np.asarray(scene.get_bounds([name]), float)
        except ValueError:  # an object without geometry cannot overlap anything
            continue
    return boxes


def build_scene_synthesizer(seed: int = 0, edge: float = 0.03) -> SynthLayout:
    """Build ``scene_synthesizer.procedural_scenes.kitchen(seed)`` closed, as a :class:`SynthLayout`;
    objects stacked on another are dropped (:func:`overlapping_objects`)."""
    from scene_synthesizer import procedural_scenes

    from .from_urdf import build_from_urdf

    with tempfile.TemporaryDirectory(prefix="react3d-ss-") as d, _asset_files_in(d):
        scene = procedural_scenes.kitchen(seed=seed)
        scene.zero_configurations()
        dropped = overlapping_objects(_object_boxes(scene))
        for name in dropped:
            scene.remove_object(f"^{re.escape(name)}$")  # anchored: never a prefix of another object
        urdf = Path(d) / "kitchen.urdf"
        scene.export(str(urdf))
        layout = build_from_urdf(urdf, seed=seed, edge=edge, kind="scene-synthesizer-kitchen")
    layout.extra["dropped_objects"] = list(dropped)
    layout.extra["dropped_overlaps"] = {k: {"overlaps": o, "fraction": f} for k, (o, f) in dropped.items()}
    return layout


@contextmanager
def _asset_files_in(folder: str) -> Iterator[None]:
    """scene-synthesizer writes every procedural door, handle and sink mesh to a random file in a
    hard-coded ``/tmp`` and never removes it (about 60 files per kitchen, thousands over a dataset).
    While a kitchen is built, its files go to ``folder`` instead, which is removed with the build."""
    from scene_synthesizer import utils

    real = utils.get_random_filename

    def into_folder(suffix: str, prefix: str = "", dir: str = "/tmp") -> str:  # noqa: A002 - the library's name
        return real(suffix, prefix=prefix, dir=folder if dir == "/tmp" else dir)

    utils.get_random_filename = into_folder
    try:
        yield
    finally:
        utils.get_random_filename = real
