"""Fronts standing on a worktop against the wall behind it are splash-back, not cabinets.

Nothing openable is set flush into the wall right above a worktop: that band is tiled or panelled
splash-back, and its sockets, switches and tile joints look like handles and seams (the tiled wall of
7-Scenes RedKitchen was taken for a top-hinged flap by the mesh rules and by the image rules alike).
A wall cabinet hangs well above the worktop. So a front is dropped when a horizontal, upward-facing
surface runs level with its bottom edge (within ``band``), above ``min_z``, and covers at least ``cover``
of a strip ``reach`` deep in front of it (``perception.heuristic.splashback``) — unless the wall stands
behind it: an appliance on the worktop (a microwave pushed back towards the wall, with worktop in front
of its door) has the wall beside and above it, ``wall_behind`` behind its door's plane, while the
splash-back is that wall. A front with at least ``wall_share`` of a ring ``wall_ring`` wide around its
sides and top covered by surface facing the same way that far behind it is kept.

A black or glossy worktop returns no depth and is not in the mesh (RedKitchen's black granite). The run
under it still is: a front whose bottom edge is level with the top of another front standing ``run_depth``
in front of it (a worktop's depth; a microwave's door is nearer the run's front line) and overlapping it
across, stands at the back of that run's worktop too. There the front's bottom edge lies above the run's top
edge by the worktop's thickness and the gap under it, up to ``worktop_rise`` more than ``band``.
"""

from __future__ import annotations

import numpy as np

from ...config.heuristic import SplashbackConfig
from ...data.mesh import TriMesh
from .fronts import Front

_PARALLEL_COS = 0.95  # fronts of one run and the wall behind it face the same way (within ~18 degrees)


def on_worktop(fronts: list[Front], mesh: TriMesh, rules: SplashbackConfig) -> list[bool]:
    """Per front: does it stand on a worktop, flush with the wall behind it (see module docstring)?
    (The rule itself, whether or not ``rules.enabled``.)"""
    if not fronts:
        return []
    n = mesh.face_normals
    up = n[:, 2] > rules.min_up  # a scanned worktop is noisy and cluttered: its faces tilt
    cen, area = mesh.face_centroids[up], mesh.face_areas[up]
    out = []
    for f in fronts:
        bottom = float(f.extent_v[0])
        if bottom < rules.min_z:
            out.append(False)
            continue
        d = (cen - f.center) @ f.n_out
        cu = cen @ f.u
        sel = ((d > rules.reach[0]) & (d < rules.reach[1]) & (cu > f.extent_u[0]) & (cu < f.extent_u[1])
               & (np.abs(cen[:, 2] - bottom) < rules.band))
        strip = max(f.w * (rules.reach[1] - rules.reach[0]), 1e-9)
        worktop = bool(area[sel].sum() >= rules.cover * strip) or _behind_run(f, fronts, rules)
        out.append(worktop and wall_behind_share(f, mesh, rules) < rules.wall_share)
    return out


def wall_behind_share(f: Front, mesh: TriMesh, rules: SplashbackConfig) -> float:
    """Share of the ring ``rules.wall_ring`` wide around ``f``'s sides and top (not below: the worktop and
    the run are there) covered by surface facing the same way, ``rules.wall_behind`` (from, to; m) behind the
    front's plane: the wall an appliance on the worktop stands in front of (see module docstring)."""
    if rules.wall_ring <= 0:
        return 0.0
    c, a = mesh.face_centroids, mesh.face_areas
    behind = -((c - f.center) @ f.n_out)
    u, v = c @ f.u, c[:, 2]
    (u0, u1), (v0, v1), r = f.extent_u, f.extent_v, rules.wall_ring
    ring = ((u > u0 - r) & (u < u1 + r) & (v > v0) & (v < v1 + r)
            & ~((u > u0) & (u < u1) & (v < v1)))
    sel = (ring & (behind > rules.wall_behind[0]) & (behind < rules.wall_behind[1])
           & (mesh.face_normals @ f.n_out > _PARALLEL_COS))
    ring_area = (f.w + 2 * r) * (f.h + r) - f.w * f.h
    return float(a[sel].sum()) / ring_area


def _behind_run(f: Front, fronts: list[Front], rules: SplashbackConfig) -> bool:
    """Whether another front of ``fronts``, parallel to ``f``, stands ``rules.run_depth`` in front of it, overlaps
    it across and has its top edge within ``rules.band`` of ``f``'s bottom edge: the run whose worktop ``f``
    stands on (see module docstring; ``run_depth`` (0, 0): off)."""
    lo, hi = rules.run_depth
    if hi <= 0:
        return False
    bottom = float(f.extent_v[0])
    for g in fronts:
        if g is f or float(g.n_out @ f.n_out) < _PARALLEL_COS:
            continue
        ahead = float((g.center - f.center) @ f.n_out)
        gu = float(g.center @ f.u)
        across = min(gu + g.w / 2, f.extent_u[1]) - max(gu - g.w / 2, f.extent_u[0])
        rise = bottom - float(g.extent_v[1])  # the worktop's thickness and the gap under it lie between
        if lo <= ahead <= hi and across > 0 and -rules.band < rise < rules.band + rules.worktop_rise:
            return True
    return False
