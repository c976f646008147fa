"""Joint geometry used by the evaluation: 3-way joint class, axis error (OE), line distance (MD)."""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..data.parts import Articulation

JointClass = Literal["prismatic", "revolute_horizontal", "revolute_vertical"]


def joint_class(art: Articulation, horizontal_deg: float = 45.0) -> JointClass:
    """Paper's taxonomy: a revolute axis is horizontal if it makes < ``horizontal_deg`` with the
    ground plane (z up); the angle with the plane is asin(|a_z|)."""
    if art.joint_type == "prismatic":
        return "prismatic"
    a = np.asarray(art.axis, float)
    elev = np.degrees(np.arcsin(min(1.0, abs(a[2]) / np.linalg.norm(a))))
    return "revolute_horizontal" if elev < horizontal_deg else "revolute_vertical"


def axis_error_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two axes in degrees, sign-agnostic (a and -a are the same axis): 0..90."""
    a = np.asarray(a, float) / np.linalg.norm(a)
    b = np.asarray(b, float) / np.linalg.norm(b)
    return float(np.degrees(np.arccos(np.clip(abs(a @ b), 0.0, 1.0))))


def line_distance(o1: np.ndarray, a1: np.ndarray, o2: np.ndarray, a2: np.ndarray, parallel_eps: float = 1e-9) -> float:
    """Shortest distance between the infinite lines o1 + t a1 and o2 + s a2 (metres).
    Parallel lines use the point-to-line distance, since the cross product vanishes."""
    o1, a1, o2, a2 = (np.asarray(v, float) for v in (o1, a1, o2, a2))
    a1 = a1 / np.linalg.norm(a1)
    a2 = a2 / np.linalg.norm(a2)
    d = o2 - o1
    n = np.cross(a1, a2)
    nn = np.linalg.norm(n)
    if nn < parallel_eps:
        return float(np.linalg.norm(np.cross(d, a1)))
    return float(abs(d @ n) / nn)
