"""Articulation refinement, exactly the paper's equations (Sec. "Articulation refinement").

With the part's OBB sides s1 >= s2 >= s3 along u1, u2, u3 and n the front normal (u1 x u2, oriented
into the cavity):
- prismatic: a' = sign(<a, n>) n, origin kept;
- prismatic the predictor calls *sliding* (a sliding door moves in its front plane): the
  paper's rule would pull it straight out of the front, 90 deg off. Instead, like the revolute rule,
  l = argmax_{v in {u1, u2}} |<a, v>| and a' = sign(<a, l>) l (on a vertical front with a horizontal
  predicted motion: the front's horizontal in-plane edge), origin kept;
- revolute: l = argmax_{v in {u1, u2}} |<a, v>|, a' = sign(<a, l>) l; the origin is the midpoint of
  the front-face edge parallel to l that is nearer to the predicted axis line, on the mid-surface
  between the slab's front and back faces.
Only flat parts (s3 < flat_ratio * s2) are refined.
"""

from __future__ import annotations

import numpy as np

from ..data.parts import OBB, Articulation


def is_flat(obb: OBB, flat_ratio: float) -> bool:
    s1, s2, s3 = obb.extents
    return s3 < flat_ratio * s2


def _sign(x: float) -> float:
    return 1.0 if x >= 0 else -1.0


def refine_prismatic(a: Articulation, n: np.ndarray) -> Articulation:
    axis = _sign(float(np.dot(a.axis, n))) * np.asarray(n, float)
    return a.model_copy(update={"axis": tuple(axis / np.linalg.norm(axis))})


def refine_sliding(a: Articulation, obb: OBB) -> Articulation:
    """Sliding (in-plane prismatic): snap onto the in-plane OBB side nearest the predicted axis, sign kept."""
    R = obb.R
    ax = np.asarray(a.axis, float)
    l = R[:, 0] if abs(np.dot(ax, R[:, 0])) >= abs(np.dot(ax, R[:, 1])) else R[:, 1]
    axis = _sign(float(np.dot(ax, l))) * l
    return a.model_copy(update={"axis": tuple(axis / np.linalg.norm(axis))})


def line_point_distance(p: np.ndarray, o: np.ndarray, d: np.ndarray) -> float:
    d = np.asarray(d, float) / np.linalg.norm(d)
    v = np.asarray(p, float) - np.asarray(o, float)
    return float(np.linalg.norm(v - np.dot(v, d) * d))


def refine_revolute(a: Articulation, obb: OBB, mid_center: np.ndarray) -> Articulation:
    """``mid_center``: the OBB centre moved onto the slab's mid-surface (handles excluded)."""
    R = obb.R
    u1, u2 = R[:, 0], R[:, 1]
    s1, s2 = obb.extents[0], obb.extents[1]
    ax = np.asarray(a.axis, float)
    if abs(np.dot(ax, u1)) >= abs(np.dot(ax, u2)):
        l, m, half = u1, u2, s2 / 2
    else:
        l, m, half = u2, u1, s1 / 2
    axis = _sign(float(np.dot(ax, l))) * l
    edges = [mid_center + half * m, mid_center - half * m]
    # the edge nearer to the predicted axis line (both are parallel to l, so point-line distance)
    dist = [line_point_distance(e, np.asarray(a.origin), ax) for e in edges]
    origin = edges[int(np.argmin(dist))]
    return a.model_copy(update={"axis": tuple(axis), "origin": tuple(origin)})


def slab_mid_and_thickness(points: np.ndarray, center: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, float]:
    """Mid-surface point and thickness of a front slab along ``n`` (into the cavity), robust to handles.

    The front and back faces each hold a large share of the vertices; protruding handles are few and
    sit on the room side (low <x, n>), so the 20th percentile lands on the front face and the maximum
    on the back face.
    """
    d = (np.asarray(points, float) - center) @ n
    front, back = float(np.percentile(d, 20)), float(d.max())
    return center + n * (front + back) / 2, max(back - front, 1e-4)
