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

DistanceFn = Callable[[np.ndarray], np.ndarray]  # world points -> distance to other geometry


def opening_sign(a: Articulation, points: np.ndarray, into_cavity: np.ndarray) -> float:
    """+1 if q > 0 moves the part out of its cavity (against ``into_cavity``), else -1."""
    q = 0.15 if a.joint_type == "revolute" else 0.05
    disp = (a.move(points, q) - points).mean(0)
    return 1.0 if np.dot(disp, into_cavity) <= 0 else -1.0


def revolute_limit(a: Articulation, points: np.ndarray, distance: DistanceFn, cfg: LimitConfig) -> tuple[float, str]:
    """Largest collision-free opening angle (radians) and its source ('sweep' or 'cap')."""
    axis, o = np.asarray(a.axis), np.asarray(a.origin)
    r = np.linalg.norm(np.cross(points - o, axis), axis=1)
    pts = points[r > 0.05]  # points near the hinge barely move and touch the carcass when closed
    if len(pts) == 0:
        return float(np.radians(cfg.revolute_max_deg)), "cap"
    free0 = distance(pts) >= cfg.collision_clearance_m
    pts = pts[free0]
    step = np.radians(cfg.revolute_step_deg)
    qmax = np.radians(cfg.revolute_max_deg)
    last = 0.0
    q = step
    while q <= qmax + 1e-9:
        if len(pts) and (distance(a.move(pts, q)) < cfg.collision_clearance_m).any():
            return max(last, step), "sweep"
        last = q
        q += step
    return float(qmax), "cap"


def set_limits(a: Articulation, points: np.ndarray, into_cavity: np.ndarray, cavity_depth: float | None,
               distance: DistanceFn | None, cfg: LimitConfig) -> Articulation:
    """Signed axis (q >= 0 opens) and [0, upper] limits for a closed part whose vertices are ``points``."""
    sign = opening_sign(a, points, into_cavity)
    a = a.model_copy(update={"axis": tuple(sign * np.asarray(a.axis))})
    if a.joint_type == "prismatic":
        depth = cavity_depth if cavity_depth is not None else 0.0
        upper = max(cfg.prismatic_min_m, depth - cfg.prismatic_margin_m)
        return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": "cavity" if cavity_depth else "min"})
    if distance is None:
        return a.model_copy(update={"lower": 0.0, "upper": float(np.radians(cfg.revolute_max_deg)), "limit_source": "cap"})
    upper, src = revolute_limit(a, points, distance, cfg)
    return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": src})
