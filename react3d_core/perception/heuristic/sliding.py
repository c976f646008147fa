"""Sliding doors from front geometry: two fronts on two tracks.

A pair of sliding doors shows as two parallel, equally tall fronts whose planes are a track apart
(one door stands a few centimetres in front of the other) and whose outlines meet or overlap a
little where one slides behind the other. Hinged doors and drawers of one run are coplanar, so a
plane offset between side-by-side fronts is the evidence. Each door of such a pair slides in its
front plane (prismatic along the front's horizontal in-plane direction) towards the other one. The
thresholds are ``perception.heuristic.sliding``.
"""

from __future__ import annotations

import numpy as np

from ...config.heuristic import SlidingConfig
from ...data.parts import Articulation
from .fronts import Front, u_overlap


def sliding_partner(f: Front, fronts: list[Front], r: SlidingConfig) -> Front | None:
    """The front ``f`` slides against, or None: parallel, a track in front of or behind it, as tall as
    it, and meeting it side by side with a small overlap or gap (not one inside the other)."""
    best, best_ov = None, -np.inf
    for g in fronts:
        if g is f or float(np.dot(g.n_out, f.n_out)) < r.min_parallel:
            continue
        off = abs(float(np.dot(g.center - f.center, f.n_out)))
        if not (r.track_offset[0] <= off <= r.track_offset[1]):
            continue
        hv = min(g.extent_v[1], f.extent_v[1]) - max(g.extent_v[0], f.extent_v[0])
        if hv < r.min_height_overlap * min(f.h, g.h) or abs(f.h - g.h) > (1 - r.min_height_overlap) * max(f.h, g.h):
            continue
        ov = u_overlap(f, g)
        if not (-r.max_gap <= ov <= min(r.max_overlap, 0.5 * min(f.w, g.w))):
            continue
        if ov > best_ov:
            best, best_ov = g, ov
    return best


def mark_sliding(fronts: list[Front], rules: SlidingConfig = SlidingConfig()) -> int:
    """Re-type fronts that have a sliding partner as sliding doors (kind ``sliding``): prismatic along
    the front's horizontal in-plane direction ``u``, towards the partner. Returns how many."""
    partner = {id(f): sliding_partner(f, fronts, rules) for f in fronts}
    n = 0
    for f in fronts:
        g = partner[id(f)]
        if g is None:
            continue
        towards = 1.0 if float((g.center - f.center) @ f.u) >= 0 else -1.0
        centre = f.center + f.u * (0.5 * sum(f.extent_u) - float(f.center @ f.u))
        centre = np.array([centre[0], centre[1], 0.5 * sum(f.extent_v)])
        f.kind = "sliding"
        f.articulation = Articulation(joint_type="prismatic", axis=towards * f.u, origin=centre, lower=0.0,
                                      upper=max(rules.min_travel, f.w - max(0.0, u_overlap(f, g))),
                                      limit_source="heuristic")
        n += 1
    return n
