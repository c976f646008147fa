"""Drawers are within reach: a drawer-shaped front high up is a strip of something else.

Drawers sit in base units, dressers and the bottom of wardrobes; nothing slides out above eye level,
where a drawer could not be looked into. The low, wide strips the shape rules type as drawers up there
are the top rail of a wardrobe or the band between a wall cabinet's doors and the ceiling, cut off by a
shadow line and given a "handle" by the cabinet's top edge (tuning scenes: 7 drawer-typed fronts with
their top above 1.5 m, all false; no ground-truth drawer there). Such fronts are dropped.
"""

from __future__ import annotations

from .fronts import Front


def drawers_within_reach(fronts: list[Front], floor: float, max_top: float) -> list[Front]:
    """``fronts`` less the drawers (``kind == "drawer"``) whose top edge is more than ``max_top`` above
    ``floor`` (``max_top`` <= 0: all kept)."""
    if max_top <= 0:
        return list(fronts)
    return [f for f in fronts if f.kind != "drawer" or f.extent_v[1] - floor <= max_top]
