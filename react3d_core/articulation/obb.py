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


def _sorted_box(center: np.ndarray, axes: np.ndarray, ext: np.ndarray) -> OBB:
    """An OBB from rows ``axes`` and ``ext``, sides sorted s1 >= s2 >= s3 in a right-handed frame."""
    order = np.argsort(-ext, kind="stable")
    R = axes[order].T.copy()
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple(center), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))


def surface_samples(triangles: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` points spread uniformly over the area of ``triangles`` (m,3,3): the surface's own
    distribution, whatever its tessellation."""
    tri = np.asarray(triangles, float)
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    if not len(tri) or area.sum() <= 0:
        return np.zeros((0, 3))
    i = rng.choice(len(tri), n, p=area / area.sum())
    s, r = np.sqrt(rng.random(n)), rng.random(n)
    return tri[i, 0] * (1 - s)[:, None] + tri[i, 1] * (s * (1 - r))[:, None] + tri[i, 2] * (s * r)[:, None]


def dense_span(x: np.ndarray, bin_m: float, min_density: float) -> tuple[float, float]:
    """(lo, hi) of the samples ``x`` without the sparse ends: bins of ``bin_m`` holding fewer than
    ``min_density`` x the median occupied bin's samples, counted from either end up to the first denser one."""
    lo, hi = float(x.min()), float(x.max())
    nb = max(1, int(np.ceil((hi - lo) / bin_m)))
    h, edges = np.histogram(x, bins=nb, range=(lo, hi))
    dense = np.flatnonzero(h >= min_density * np.median(h[h > 0]))
    return float(edges[dense[0]]), float(edges[dense[-1] + 1])


def trim_sparse_ends(obb: OBB, triangles: np.ndarray, min_density: float, min_trim_m: float, bin_m: float = 0.005,
                     samples: int = 20000) -> OBB:
    """``obb`` ending where the part's surface does along its two front sides (s1, s2).

    A mask's edge on a scan mesh takes whole triangles, and one that bridges the seam to a neighbour (a
    sliver from a flap's corner down to the drawer below it) stretches the box over that neighbour: the
    hinge, the cavity and the front then lie partly in front of the other part. Along each front side, an
    end whose surface is sparse (bins under ``min_density`` of the median, by area, not by vertex count) for
    at least ``min_trim_m`` is cut off the box; the thickness axis is left alone (handles)."""
    samples_xyz = surface_samples(triangles, samples, np.random.default_rng(0))  # fixed: the same box every run
    if len(samples_xyz) < 100:
        return obb
    R, c, ext = obb.R, np.asarray(obb.center, float), np.asarray(obb.extents, float)
    local = (samples_xyz - c) @ R
    lo, hi = -ext / 2, ext / 2
    changed = False
    for k in (0, 1):
        if ext[k] <= 2 * bin_m:
            continue
        a, b = dense_span(local[:, k], bin_m, min_density)
        if a - lo[k] >= min_trim_m:
            lo[k], changed = a, True
        if hi[k] - b >= min_trim_m:
            hi[k], changed = b, True
    if not changed:
        return obb
    return _sorted_box(c + R @ ((lo + hi) / 2), R.T, hi - lo)
