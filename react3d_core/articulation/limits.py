"""Motion limits (the paper leaves them open): how far each part can really move.

Revolute: sweep the part's points in steps and stop before any point that was free when closed comes
within ``collision_clearance_m`` of other scene geometry (background, carcass, neighbours), capped at
``revolute_max_deg``; the axis is signed first so that q > 0 swings the part out of its cavity.
Prismatic: the cavity depth minus a margin. ``limit_source`` records which rule set the limit.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..config import LimitConfig
from ..data.parts import Articulation

# world points -> distance to other geometry, or (distance, closest points) to know where it lies
DistanceFn = Callable[[np.ndarray], "np.ndarray | tuple[np.ndarray, np.ndarray]"]


def _blocked(a: Articulation, moved: np.ndarray, q: float, distance: DistanceFn, thresh: np.ndarray) -> bool:
    """Any point nearer than its threshold to geometry that lies ahead of it: within 60 deg of its
    motion and within 2 mm of its plane of motion (a revolute point moves at a fixed height along the axis).

    Geometry beside the path (the head trim a room door glides under, the floor under its bottom
    edge) does not stop the part; only what the point is moving into does."""
    res = distance(moved)
    if not isinstance(res, tuple):
        return bool((res < thresh).any())
    d, cp = res
    near = d < thresh
    if not near.any():
        return False
    vel = a.move(moved[near], 1e-3) - moved[near]
    to = cp[near] - moved[near]
    cos = (vel * to).sum(1) / np.maximum(np.linalg.norm(vel, axis=1) * np.linalg.norm(to, axis=1), 1e-12)
    axial = np.abs(to @ np.asarray(a.axis, float))
    return bool(((cos > 0.5) & (axial < 0.002)).any())


def opening_sign(a: Articulation, points: np.ndarray, into_cavity: np.ndarray) -> float:
    """+1 if q > 0 moves the part out of its cavity (against ``into_cavity``), else -1."""
    q = 0.15 if a.joint_type == "revolute" else 0.05
    disp = (a.move(points, q) - points).mean(0)
    return 1.0 if np.dot(disp, into_cavity) <= 0 else -1.0


def revolute_limit(a: Articulation, points: np.ndarray, distance: DistanceFn, cfg: LimitConfig,
                   closed_distance: DistanceFn | None = None) -> tuple[float, str]:
    """Largest collision-free opening angle (radians) and its source ('sweep' or 'cap').

    A point blocks the sweep when it comes nearer to other geometry than both the clearance and its own
    distance when closed (``closed_distance``, default ``distance``), less 2 mm: a door bottom that
    glides 1 cm above the floor may keep gliding, it only may not get nearer."""
    axis, o = np.asarray(a.axis), np.asarray(a.origin)
    r = np.linalg.norm(np.cross(points - o, axis), axis=1)
    pts = points[r > 0.05]  # points near the hinge barely move and touch the carcass when closed
    if len(pts) == 0:
        return float(np.radians(cfg.revolute_max_deg)), "cap"
    d0 = (closed_distance or distance)(pts)
    d0 = d0[0] if isinstance(d0, tuple) else d0
    thresh = np.minimum(cfg.collision_clearance_m, d0) - 0.002
    keep = thresh > 0
    pts, thresh = pts[keep], thresh[keep]
    step = np.radians(cfg.revolute_step_deg)
    qmax = np.radians(cfg.revolute_max_deg)
    last = 0.0
    q = step
    while q <= qmax + 1e-9:
        if len(pts) and _blocked(a, a.move(pts, q), q, distance, thresh):
            return max(last, step), "sweep"
        last = q
        q += step
    return float(qmax), "cap"


def set_limits(a: Articulation, points: np.ndarray, into_cavity: np.ndarray, cavity_depth: float | None,
               distance: DistanceFn | None, cfg: LimitConfig, closed_distance: DistanceFn | None = None) -> Articulation:
    """Signed axis (q >= 0 opens) and [0, upper] limits for a closed part whose vertices are ``points``."""
    sign = opening_sign(a, points, into_cavity)
    a = a.model_copy(update={"axis": tuple(sign * np.asarray(a.axis))})
    if a.joint_type == "prismatic":
        depth = cavity_depth if cavity_depth is not None else 0.0
        upper = max(cfg.prismatic_min_m, depth - cfg.prismatic_margin_m)
        return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": "cavity" if cavity_depth else "min"})
    if distance is None:
        return a.model_copy(update={"lower": 0.0, "upper": float(np.radians(cfg.revolute_max_deg)), "limit_source": "cap"})
    upper, src = revolute_limit(a, points, distance, cfg, closed_distance)
    return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": src})
