"""Which moving links an episode can reach, so that the others sit out of its contacts.

An episode moves little: one joint (and what hangs on it) through its range, or a probe through a
cavity or at a front, while every other joint is held at 0. A link held at 0 that nothing of the
episode can come near cannot change what is measured (the driven link's reach, penetration and contacts,
the probe's path), but its colliders still cost the engine a narrow phase against their carcass and the
background every step. :func:`needed` keeps the links whose colliders (world boxes at q = 0) come within
``margin`` of the episode's region: the box swept by the driven link's colliders over its range,
widened by ``overshoot`` of the range each side, and the probe's path. :func:`stayed_inside` then
checks that the episode really stayed inside what was assumed; when it did not, the episode is run
again with every collider on (``drive.py``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from .sim import SimJoint

Box = np.ndarray
"""An axis-aligned box in world coordinates: a 2x3 array (lower corner, upper corner)."""

STEP_RAD = math.radians(2.0)
"""Angle between the sampled poses of a rotating box; the arc between two samples bulges past their
chord by at most ``r (1 - cos(STEP_RAD / 2))`` (0.15 mm at 1 m), which is added to the swept box."""


def corners(box: Box) -> np.ndarray:
    lo, hi = np.asarray(box, float)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def merge(boxes: Iterable[Box]) -> Box | None:
    bs = [np.asarray(b, float) for b in boxes]
    if not bs:
        return None
    return np.array([np.min([b[0] for b in bs], axis=0), np.max([b[1] for b in bs], axis=0)])


def grow(box: Box, by: float) -> Box:
    return np.asarray(box, float) + np.array([[-by] * 3, [by] * 3])


def overlaps(a: Box, b: Box) -> bool:
    """Closed boxes: touching faces overlap."""
    return bool(np.all(a[0] <= b[1]) and np.all(b[0] <= a[1]))


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: rotation by ``angle`` about the unit ``axis``."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def swept(box: Box, joint: SimJoint, q0: float, q1: float) -> Box:
    """The box a rigid body's ``box`` (at joint value 0) covers while ``joint`` moves from ``q0`` to ``q1``."""
    lo, hi = min(q0, q1), max(q0, q1)
    pts = corners(box)
    axis = np.asarray(joint.axis, float) / np.linalg.norm(joint.axis)
    anchor = np.asarray(joint.anchor, float)
    if joint.joint_type == "prismatic":
        return merge([np.array([p.min(0), p.max(0)]) for p in (pts + lo * axis, pts + hi * axis)])  # type: ignore[return-value]
    n = max(1, int(math.ceil((hi - lo) / STEP_RAD)))
    rel = pts - anchor
    out = []
    for q in np.linspace(lo, hi, n + 1):
        p = rel @ rotation(axis, float(q)).T + anchor
        out.append(np.array([p.min(0), p.max(0)]))
    r = float(np.max(np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)))
    return grow(merge(out), r * (1 - math.cos((hi - lo) / n / 2)))  # type: ignore[arg-type]


def motion_range(goal: float, overshoot: float) -> tuple[float, float]:
    """Joint values a driven joint is assumed to stay within: 0 to its goal, widened by ``overshoot``
    of the range at each end."""
    lo, hi = min(0.0, goal), max(0.0, goal)
    pad = overshoot * (hi - lo)
    return lo - pad, hi + pad


def needed(boxes: dict[str, Box], region: Box, margin: float, keep: Iterable[str] = ()) -> frozenset[str]:
    """Links of ``boxes`` within ``margin`` of ``region``, and ``keep``."""
    r = grow(region, margin)
    return frozenset(keep) | frozenset(n for n, b in boxes.items() if overlaps(np.asarray(b, float), r))


def stayed_inside(q: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Every joint value (rows: time, columns: joints, or one row) within its assumed range."""
    q = np.atleast_2d(np.asarray(q, float))
    return bool(np.all(np.isfinite(q)) and np.all(q >= lo) and np.all(q <= hi))
