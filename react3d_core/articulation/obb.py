"""Minimal-volume oriented box for (nearly) planar parts that never degenerates.

Candidate box normals are the PCA normal (smallest variance) and the normals of the convex hull's
facets (a minimal box has a face flush with the hull, O'Rourke); for each the in-plane axes come from
the minimum-area rectangle of the projected points (rotating calipers, OpenCV), and the smallest box
wins. PCA alone tilts the box when a handle sticks out of one side of a door; a flat or collinear
cloud (no hull) keeps the PCA box. Sides are sorted s1 >= s2 >= s3 and the axes form a right-handed frame.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..data.parts import OBB
from ..geometry import triangle_areas


def min_obb(points: np.ndarray) -> OBB:
    """OBB of ``points`` (N,3), N >= 1; a flat or collinear cloud gives zero-size sides, not an error."""
    p = np.asarray(points, float)
    c0 = p.mean(0)
    q = p - c0
    if len(p) < 3 or np.allclose(q, 0):
        return OBB(center=tuple(c0), axes=((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0)), extents=(0.0, 0.0, 0.0))
    _, _, vt = np.linalg.svd(q, full_matrices=False)
    best = _box_for_normal(q, vt[2], vt[0])
    h = _hull(q)
    if h is not None:
        hv = q[h.vertices]
        for n in _hull_normals(q, h):
            cand = _box_for_normal(hv, n, None)
            if cand[2] < best[2] * (1 - 1e-6):
                best = cand
    axes, _, _ = best
    proj = q @ axes.T
    lo, hi = proj.min(0), proj.max(0)
    center = c0 + ((lo + hi) / 2) @ axes
    ext = hi - lo
    order = np.argsort(-ext, kind="stable")
    R = axes[order].T.copy()
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple(center), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))


def _box_for_normal(q: np.ndarray, n: np.ndarray, e1: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, float]:
    """(3x3 axes as rows, extents, volume) of the smallest box of ``q`` with one axis along ``n``."""
    n = n / np.linalg.norm(n)
    if e1 is None:
        e1 = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    e1 = e1 - np.dot(e1, n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    uv = np.stack([q @ e1, q @ e2], 1).astype(np.float32)
    _, _, ang = cv2.minAreaRect(uv)
    t = np.radians(ang)
    a = np.cos(t) * e1 + np.sin(t) * e2
    b = -np.sin(t) * e1 + np.cos(t) * e2
    axes = np.stack([a, b, n])
    proj = q @ axes.T
    ext = proj.max(0) - proj.min(0)
    return axes, ext, float(np.prod(ext))


def _hull(q: np.ndarray):  # noqa: ANN202
    from scipy.spatial import ConvexHull, QhullError

    try:
        return ConvexHull(q)
    except (QhullError, ValueError):
        return None


def _hull_normals(q: np.ndarray, h, max_normals: int = 48) -> np.ndarray:  # noqa: ANN001
    """Distinct normals of the convex hull's (``h``) largest facets.

    Bounded so a noisy part with a hull of thousands of facets stays cheap; the facets that decide a
    slab's box (its front and back, the sides) are the large ones."""
    n = h.equations[:, :3]
    n = n * np.where(n[:, [0]] < 0, -1.0, 1.0)  # n and -n give the same box
    area = triangle_areas(q, h.simplices)
    key, inv = np.unique(np.round(n, 3), axis=0, return_inverse=True)
    total = np.bincount(inv.ravel(), weights=area, minlength=len(key))
    return key[np.argsort(-total, kind="stable")[:max_normals]]
