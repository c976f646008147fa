"""Labels and names of the interactive objects: ``drawer_03`` instead of ``obj_003``.

A label says what the part is, from the evidence the pipeline has (joint type and axis, the front's
size and height above the floor, and a perception tag when a model named the part). Rules, in order
(conservative: an appliance only when the evidence is specific):

1. a sliding part (prismatic in its own front plane) is a ``sliding_door``;
2. any other prismatic part is a ``drawer``;
3. a revolute part whose perception tag names an appliance (fridge / refrigerator / freezer,
   oven, dishwasher, microwave) is that appliance's door (``fridge_door``, ...);
4. a revolute part hinged about an axis within 45 deg of vertical is a ``door``;
5. a revolute part hinged about a horizontal axis at its bottom edge, ``appliance_width_m`` wide,
   whose top edge is at most ``appliance_max_top_m`` above the floor (under a worktop), is an
   appliance door: a ``dishwasher_door`` if its bottom edge is within ``dishwasher_max_bottom_m``
   of the floor and it is at least ``dishwasher_min_height_m`` tall, else an ``oven_door`` if it is
   at least ``oven_min_height_m`` tall (cabinets under a worktop have side-hinged doors and
   drawers; a front that drops open there is an appliance);
6. any other horizontally hinged part is a ``flap``.
Fridge and microwave doors are side-hinged like cabinet doors, so geometry alone never names them.

Names: ``<label>_<nn>``, numbered from 01 per label in a spatial order that does not depend on
detection order: by x, then y (both on a 5 cm grid, so a column of drawers shares a key), then
from the top down. Link and joint names of the export are built from it (``drawer_03``,
``drawer_03_joint``, ``drawer_03_base``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np

from ..config.assembly import AssemblyConfig
from ..data.mesh import TriMesh
from ..data.parts import Articulation

LABELS = ("door", "drawer", "flap", "sliding_door", "fridge_door", "oven_door", "dishwasher_door", "microwave_door")
TAGS = {"fridge": "fridge_door", "refrigerator": "fridge_door", "freezer": "fridge_door", "oven": "oven_door",
        "dishwasher": "dishwasher_door", "microwave": "microwave_door"}
UP = np.array([0.0, 0.0, 1.0])
GRID_M = 0.05


def floor_height(mesh: TriMesh, up: np.ndarray = UP) -> float:
    """Height of the floor: the area-weighted 2nd percentile of the heights of upward-facing faces
    (the floor is the lowest large horizontal surface; a stray low face does not move it). Without
    upward faces, the lowest vertex."""
    n = mesh.face_cross
    area = np.linalg.norm(n, axis=1)
    upward = (n @ up) > 0.9 * np.maximum(area, 1e-300)
    if not upward.any():
        return float((mesh.vertices @ up).min())
    h = mesh.face_centroids[upward] @ up
    w = area[upward]
    order = np.argsort(h)
    cum = np.cumsum(w[order])
    return float(h[order][np.searchsorted(cum, 0.02 * cum[-1])])


def appliance_tag(tag: str | None) -> str | None:
    """The appliance door a perception tag names (``"refrigerator door"`` -> ``fridge_door``), or None."""
    for word in re.split(r"[^a-z]+", (tag or "").lower()):
        if word in TAGS:
            return TAGS[word]
    return None


def part_label(art: Articulation, center: np.ndarray, u: np.ndarray, v: np.ndarray, su: float, sv: float,
               sliding: bool, floor: float, config: AssemblyConfig, tag: str | None = None, up: np.ndarray = UP) -> str:
    """The label of one part (rules in the module doc). ``center``, ``u``, ``v``, ``su``, ``sv``: the
    front's centre, in-plane axes and extents; ``floor``: floor height; ``tag``: perception's label."""
    if art.joint_type == "prismatic":
        return "sliding_door" if sliding else "drawer"
    named = appliance_tag(tag)
    if named is not None:
        return named
    axis = np.asarray(art.axis, float)
    if abs(float(axis @ up)) >= np.cos(np.radians(45)):
        return "door"
    u, v = np.asarray(u, float), np.asarray(v, float)
    vertical_is_v = abs(float(v @ up)) >= abs(float(u @ up))
    vert, height, width = (v, sv, su) if vertical_is_v else (u, su, sv)
    if abs(float(vert @ up)) < 0.5:  # the front faces up or down (a lid): no bottom edge
        return "flap"
    mid = float(np.asarray(center, float) @ up)
    hinge = float(np.asarray(art.origin, float) @ up)
    bottom, top = mid - height / 2 - floor, mid + height / 2 - floor
    lo_w, hi_w = config.appliance_width_m
    if hinge < mid and lo_w <= width <= hi_w and top <= config.appliance_max_top_m:
        if bottom <= config.dishwasher_max_bottom_m and height >= config.dishwasher_min_height_m:
            return "dishwasher_door"
        if height >= config.oven_min_height_m:
            return "oven_door"
    return "flap"


def spatial_key(center: Sequence[float]) -> tuple[int, int, float]:
    """Sort key: x, then y on a ``GRID_M`` grid, then from the top down."""
    c = np.asarray(center, float)
    return int(np.floor(c[0] / GRID_M)), int(np.floor(c[1] / GRID_M)), -float(c[2])


def object_ids(labels: Sequence[str], centers: Sequence[Sequence[float]]) -> list[str]:
    """``<label>_<nn>`` per part, numbered from 1 per label in spatial order (``spatial_key``)."""
    order = sorted(range(len(labels)), key=lambda i: (spatial_key(centers[i]), i))
    counts = {lab: labels.count(lab) for lab in set(labels)}
    seen: dict[str, int] = {}
    out = [""] * len(labels)
    for i in order:
        lab = labels[i]
        seen[lab] = seen.get(lab, 0) + 1
        out[i] = f"{lab}_{seen[lab]:0{max(2, len(str(counts[lab])))}d}"
    return out
