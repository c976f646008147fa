"""Motion limits (the paper leaves them open): how far each part can really move.

The axis is signed first so that q > 0 moves the part out of its cavity. Then:

- revolute: sweep the part's points (its hull vertices, so the free edge, corners and handle tips are
  never missed, plus a sample of the rest) and stop before any point that was free when closed comes
  within ``collision_clearance_m`` of other scene geometry it moves into (a wall, a neighbour's front,
  the worktop, the floor), capped at ``revolute_max_deg``. Samples advance conservatively (no point can
  pass its threshold before the next one), at least so far that the fastest point moves ``sweep_step_m``
  (half the band in which it blocks: it lands in the band, never on or in an obstacle, so nothing thin is
  stepped over) and at most ``revolute_step_deg``;
- prismatic: the cavity depth, never more than the furniture's own depth (``body_depth``, the cavity
  stage's d_body) and, where that depth was not measured, never more than ``prismatic_max_m``; less
  ``prismatic_margin_m``; then the same sweep along the axis (a drawer at an inside corner runs into the
  other run's fronts, one facing an island into the island).

A part whose sweep is blocked before ``revolute_min_deg`` / ``prismatic_min_m`` (the minimum useful
range) is reported ``blocked``: it keeps its free range, or, when even the first sample collides, the
range over which no point moves more than the clearance (the exported joint needs a range > 0, and the
part goes no deeper than the clearance into what blocks it). ``limit_source`` records which rule set the
limit: ``sweep``, ``cap``, ``cavity``, ``body``, ``prior``, ``min``, ``blocked``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..config import LimitConfig
from ..data.parts import Articulation

# world points -> distance to other geometry, or (distance, closest points) to know where it lies
DistanceFn = Callable[[np.ndarray], "np.ndarray | tuple[np.ndarray, np.ndarray]"]


def sweep_points(points: np.ndarray, max_points: int, rng: np.random.Generator) -> np.ndarray:
    """The points a sweep follows: the convex hull's vertices of ``points`` (the extremes, which meet an
    obstacle first) and a random sample of the rest, ``max_points`` in all (the hull first)."""
    p = np.asarray(points, float)
    if len(p) <= max_points:
        return p
    hull = _hull_vertices(p)[:max_points]
    rest = np.setdiff1d(np.arange(len(p)), hull)
    k = max_points - len(hull)
    extra = rng.choice(rest, k, replace=False) if k > 0 and len(rest) else np.zeros(0, np.int64)
    return p[np.concatenate([hull, extra])]


def _hull_vertices(p: np.ndarray) -> np.ndarray:
    from scipy.spatial import ConvexHull, QhullError

    try:
        return np.asarray(ConvexHull(p).vertices, np.int64)
    except (QhullError, ValueError):  # flat or degenerate cloud: its extremes along each axis
        return np.unique(np.concatenate([p.argmin(0), p.argmax(0)]))


def _blocked(a: Articulation, moved: np.ndarray, res: np.ndarray | tuple[np.ndarray, np.ndarray],
             thresh: np.ndarray) -> bool:
    """Any point nearer than its threshold to geometry that lies ahead of it (``res``: the distance
    function's answer at ``moved``): within 60 deg of its motion and, for a revolute point (which moves
    at a fixed height along the axis), within 2 mm of its plane of motion.

    Geometry beside the path (the head trim a room door glides under, the floor under its bottom
    edge, a worktop above a drawer) does not stop the part; only what the point is moving into does."""
    if not isinstance(res, tuple):
        return bool((res < thresh).any())
    d, cp = res
    near = d < thresh
    if not near.any():
        return False
    vel = a.move(moved[near], 1e-3) - moved[near]
    to = cp[near] - moved[near]
    cos = (vel * to).sum(1) / np.maximum(np.linalg.norm(vel, axis=1) * np.linalg.norm(to, axis=1), 1e-12)
    # a point on a surface (|to| ~ 0, float32 closest points) glides in its plane: the sweep lands every
    # point that moves into something in its band first (:func:`_sweep`), never on it
    ahead = (cos > 0.5) & (np.linalg.norm(to, axis=1) > 1e-4)
    if a.joint_type == "revolute":
        ahead &= np.abs(to @ np.asarray(a.axis, float)) < 0.002
    return bool(ahead.any())


def opening_sign(a: Articulation, points: np.ndarray, into_cavity: np.ndarray) -> float:
    """+1 if q > 0 moves the part out of its cavity (against ``into_cavity``), else -1."""
    q = 0.15 if a.joint_type == "revolute" else 0.05
    disp = (a.move(points, q) - points).mean(0)
    return 1.0 if np.dot(disp, into_cavity) <= 0 else -1.0


def _thresholds(pts: np.ndarray, distance: DistanceFn, closed_distance: DistanceFn | None,
                clearance: float) -> tuple[np.ndarray, np.ndarray]:
    """Points that may block (free when closed) and their thresholds: the clearance, or their distance
    when closed if nearer, less 2 mm (a door bottom that glides 1 cm above the floor may keep gliding)."""
    d0 = (closed_distance or distance)(pts)
    d0 = d0[0] if isinstance(d0, tuple) else d0
    thresh = np.minimum(clearance, d0) - 0.002
    keep = thresh > 0
    return pts[keep], thresh[keep]


def _sweep(a: Articulation, pts: np.ndarray, thresh: np.ndarray, distance: DistanceFn, qmax: float,
           fine: float, coarse: float) -> float | None:
    """The last sample q in (0, qmax] before the first blocked one (0.0 if the first is blocked), or None
    when nothing blocks up to ``qmax``.

    Conservative advancement: from each sample the next is as far as no point can come within its
    threshold of anything (its distance less the threshold over its speed: the radius about a revolute
    axis, 1 along a prismatic one), at least ``fine`` (the point that moves fastest moves
    ``sweep_step_m``, half the band where it blocks: from the band's edge it lands in the band, not on
    or in the obstacle) and at most ``coarse``. Far from everything the sweep takes few samples; near an
    obstacle, fine ones."""
    if not len(pts):
        return None
    speed = (np.linalg.norm(np.cross(pts - np.asarray(a.origin), np.asarray(a.axis)), axis=1)
             if a.joint_type == "revolute" else np.ones(len(pts)))
    speed = np.maximum(speed, 1e-6)

    def advance(res: np.ndarray | tuple[np.ndarray, np.ndarray]) -> float:
        d = res[0] if isinstance(res, tuple) else res
        room = np.where(np.isfinite(d), (d - thresh) / speed, np.inf)
        return float(np.clip(room.min(), fine, coarse)) if np.isfinite(room.min()) else coarse

    q, dq = 0.0, advance(distance(pts))
    while q < qmax - 1e-12:
        nxt = min(qmax, q + dq)
        moved = a.move(pts, nxt)
        res = distance(moved)
        if _blocked(a, moved, res, thresh):
            return q
        q, dq = nxt, advance(res)
    return None


def revolute_limit(a: Articulation, points: np.ndarray, distance: DistanceFn, cfg: LimitConfig,
                   closed_distance: DistanceFn | None = None) -> tuple[float, str]:
    """Largest collision-free opening angle (radians) and its source ('sweep', 'cap' or 'blocked').

    A point blocks the sweep when it comes nearer to other geometry than both the clearance and its own
    distance when closed (``closed_distance``, default ``distance``), less 2 mm."""
    axis, o = np.asarray(a.axis), np.asarray(a.origin)
    r = np.linalg.norm(np.cross(points - o, axis), axis=1)
    qmax = float(np.radians(cfg.revolute_max_deg))
    pts = points[r > 0.05]  # points near the hinge barely move and touch the carcass when closed
    if len(pts) == 0:
        return qmax, "cap"
    rmax = float(r.max())
    pts, thresh = _thresholds(pts, distance, closed_distance, cfg.collision_clearance_m)
    coarse = float(np.radians(cfg.revolute_step_deg))
    free = _sweep(a, pts, thresh, distance, qmax, min(coarse, cfg.sweep_step_m / rmax), coarse)
    if free is None:
        return qmax, "cap"
    if free < np.radians(cfg.revolute_min_deg):
        return max(free, cfg.collision_clearance_m / rmax), "blocked"
    return free, "sweep"


def prismatic_travel(cavity_depth: float | None, body_depth: float | None, cfg: LimitConfig) -> tuple[float, str]:
    """Travel allowed by the cavity and the furniture's depth, before any sweep, and which bound set it.

    ``cavity_depth`` None: no cavity estimate (``prismatic_min_m``). ``body_depth`` None or inf: the
    furniture's depth was not measured, so ``prismatic_max_m`` stands in for it (a ray that flew through
    an unseen back to a far wall must not give a drawer a metre of travel)."""
    if cavity_depth is None:
        return cfg.prismatic_min_m, "min"
    body_known = body_depth is not None and bool(np.isfinite(body_depth))
    cap = float(body_depth) if body_known else cfg.prismatic_max_m + cfg.prismatic_margin_m
    depth, src = (float(cavity_depth), "cavity") if cavity_depth <= cap else (cap, "body" if body_known else "prior")
    travel = depth - cfg.prismatic_margin_m
    if travel < cfg.prismatic_min_m:
        travel, src = min(cfg.prismatic_min_m, depth), "min"  # never past the back of what holds it
    return float(max(travel, 1e-3)), src


def prismatic_limit(a: Articulation, points: np.ndarray, travel: float, distance: DistanceFn, cfg: LimitConfig,
                    closed_distance: DistanceFn | None = None) -> tuple[float, str | None]:
    """Collision-free travel along the (signed) axis up to ``travel``: (travel, None) when nothing is in
    the way, else the free travel and 'sweep' (or 'blocked' below ``prismatic_min_m``)."""
    pts, thresh = _thresholds(np.asarray(points, float), distance, closed_distance, cfg.collision_clearance_m)
    fine = max(min(cfg.sweep_step_m, travel), 1e-4)
    free = _sweep(a, pts, thresh, distance, travel, fine, max(fine, 0.1 * travel))
    if free is None:
        return travel, None
    if free < cfg.prismatic_min_m:
        return max(free, cfg.collision_clearance_m), "blocked"
    return free, "sweep"


def set_limits(a: Articulation, points: np.ndarray, into_cavity: np.ndarray, cavity_depth: float | None,
               distance: DistanceFn | None, cfg: LimitConfig, closed_distance: DistanceFn | None = None,
               body_depth: float | None = None) -> Articulation:
    """Signed axis (q >= 0 opens) and [0, upper] limits for a closed part whose vertices are ``points``
    (:func:`sweep_points` picks them); ``body_depth``: the furniture's depth behind the front (d_body)."""
    sign = opening_sign(a, points, into_cavity)
    a = a.model_copy(update={"axis": tuple(sign * np.asarray(a.axis))})
    if a.joint_type == "prismatic":
        upper, src = prismatic_travel(cavity_depth, body_depth, cfg)
        if distance is not None:
            upper, swept = prismatic_limit(a, points, upper, distance, cfg, closed_distance)
            src = swept or src
        return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": src})
    if distance is None:
        return a.model_copy(update={"lower": 0.0, "upper": float(np.radians(cfg.revolute_max_deg)), "limit_source": "cap"})
    upper, src = revolute_limit(a, points, distance, cfg, closed_distance)
    return a.model_copy(update={"lower": 0.0, "upper": float(upper), "limit_source": src})
