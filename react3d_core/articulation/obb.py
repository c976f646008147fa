"""Minimal-area oriented box for (nearly) planar parts that never degenerates.

PCA gives the plane normal (smallest variance); the in-plane axes come from the minimum-area
rectangle of the projected points (rotating calipers, OpenCV). Sides are sorted s1 >= s2 >= s3 and
the axes form a right-handed frame.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..data.parts import OBB


def min_obb(points: np.ndarray) -> OBB:
    """OBB of ``points`` (N,3), N >= 1; a flat or collinear cloud gives zero-size sides, not an error."""
    p = np.asarray(points, float)
    c0 = p.mean(0)
    q = p - c0
    if len(p) < 3 or np.allclose(q, 0):
        return OBB(center=tuple(c0), axes=((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0)), extents=(0.0, 0.0, 0.0))
    _, _, vt = np.linalg.svd(q, full_matrices=False)
    e1, e2, e3 = vt[0], vt[1], np.cross(vt[0], vt[1])
    uv = np.stack([q @ e1, q @ e2], 1).astype(np.float32)
    (cx, cy), (w, h), ang = cv2.minAreaRect(uv)
    t = np.radians(ang)
    a = np.cos(t) * e1 + np.sin(t) * e2
    b = -np.sin(t) * e1 + np.cos(t) * e2
    axes = [a, b, e3]
    proj = np.stack([q @ ax for ax in axes], 1)
    lo, hi = proj.min(0), proj.max(0)
    center = c0 + sum(ax * (l + h_) / 2 for ax, l, h_ in zip(axes, lo, hi))
    ext = hi - lo
    order = np.argsort(-ext, kind="stable")
    R = np.stack([axes[i] for i in order], 1)
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple(center), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))
