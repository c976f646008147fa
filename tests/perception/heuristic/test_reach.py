"""Drawers are within reach (hand-built fronts)."""

from __future__ import annotations

import numpy as np

from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.reach import drawers_within_reach


def _front(z0: float, z1: float, kind: str) -> Front:
    return Front(facet=-1, handle_facets=[], center=np.array([0.5, 0.0, (z0 + z1) / 2]), n_out=np.array([0.0, -1.0, 0.0]),
                 u=np.array([1.0, 0.0, 0.0]), extent_u=(0.0, 1.0), extent_v=(z0, z1), kind=kind)


def test_drawers_above_eye_level_are_dropped_other_fronts_stay() -> None:
    """Floor at 0.05 m, limit 1.7 m: a drawer from 1.55 to 1.74 m tops out 1.69 above the floor
    (kept), one up to 1.76 m is 1.71 above it (dropped); a wall-cabinet door and a flap up there stay,
    and a base drawer stays."""
    keep_edge, high, door, flap, base = (_front(1.55, 1.74, "drawer"), _front(1.60, 1.76, "drawer"),
                                         _front(1.4, 2.1, "door"), _front(1.8, 2.2, "flap"), _front(0.6, 0.8, "drawer"))
    assert drawers_within_reach([keep_edge, high, door, flap, base], 0.05, 1.7) == [keep_edge, door, flap, base]
    assert drawers_within_reach([high], 0.05, 0.0) == [high]
