"""Gravity prior for the box of a vertical front: keep it upright unless the minimal box is clearly smaller.

The minimal-volume box of a door that fusion segmented a few centimetres too wide at one corner, or of a
near-square door, is rotated 3-9 degrees in the front plane; the refinement then snaps the hinge axis
onto that rotated edge (the large kitchens' ``obb_tilt`` joint errors). Cabinet fronts in a
gravity-aligned scan (z up) are upright, so the upright box wins unless the minimal one is smaller by
more than ``tolerance`` of its volume.
"""

from __future__ import annotations

import numpy as np

from ..data.parts import OBB

UP = np.array([0.0, 0.0, 1.0])


PLANE_VERTICAL = float(np.sin(np.radians(5.0)))
"""A clipping plane whose normal has |n_z| at most this is a vertical front's plane."""

PLANE_AGREES = float(np.cos(np.radians(5.0)))
"""A box whose thinnest axis is within 5 degrees of the front's plane normal agrees with it."""


def upright_box(points: np.ndarray, obb: OBB, tolerance: float, max_tilt: float = 0.25,
                plane_normal: np.ndarray | None = None) -> OBB:
    """``obb``, or the gravity-aligned box (normal horizontal, one side vertical) of ``points`` when the
    front is vertical (|n_z| <= ``max_tilt`` for its thinnest axis n) and the upright box's volume is at
    most ``(1 + tolerance)`` times ``obb``'s. Sides sorted s1 >= s2 >= s3, right-handed, as ``min_obb``.

    ``plane_normal``: the front's own plane (the segmentation's clipping plane, fitted to the front face).
    When that plane is vertical and ``obb`` does not lie along it (a stray triangle reaching behind one
    corner, or a handle, makes a box tilted 15 degrees the smallest), the box is the upright one facing
    along the plane, whatever the volumes: the front face is the evidence, the minimal volume is not."""
    n = obb.R[:, 2]
    if tolerance <= 0:
        return obb
    pn = None if plane_normal is None else np.asarray(plane_normal, float) / np.linalg.norm(plane_normal)
    by_plane = pn is not None and abs(pn[2]) <= PLANE_VERTICAL and abs(float(n @ pn)) < PLANE_AGREES
    if not by_plane and abs(n[2]) > max_tilt:
        return obb
    n_h = np.array([pn[0], pn[1], 0.0]) if by_plane else np.array([n[0], n[1], 0.0])
    n_h /= np.linalg.norm(n_h)
    axes = np.stack([n_h, np.cross(UP, n_h), UP])
    p = np.asarray(points, float)
    proj = p @ axes.T
    lo, hi = proj.min(0), proj.max(0)
    ext = hi - lo
    if not by_plane and np.prod(ext) > (1.0 + tolerance) * np.prod(obb.extents):
        return obb
    center = ((lo + hi) / 2) @ axes
    order = np.argsort(-ext, kind="stable")
    R = axes[order].T.copy()
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple(center), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))
