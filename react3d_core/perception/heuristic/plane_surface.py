"""The scan surface at a plane, on the plane's orthophoto grid: rays cast along the plane's normal through
every grid pixel, so what the image path knows of a plane does not depend on how the scan is triangulated.

Why: where a plane is (its coverage) and the handles standing out of it were splatted from the mesh's
face centroids on the 4 mm grid, holes closed up to 2 cm. A quadric-decimated scan has 3-5 cm faces on
flat fronts and walls, so its planes came out 0-13 % covered (RedKitchen at 100k faces: not one front).
A ray through every pixel sees the surface itself, whatever its triangles.

Two casts per pixel, both towards the plane (along -n):

- the **plane cast** starts ``tol`` in front of the plane and ends ``tol`` behind it: the first surface in
  that slab, so a handle standing further out does not hide the plane behind it where that was scanned;
- the **front cast** starts ``front`` in front and ends ``behind`` the plane: the front-most surface near the
  plane, where handles in the mesh stand out.

Where the plane is: the plane cast's hits whose surface is not tilted by more than the plane's angle
tolerance, the tilt measured on the hit offsets averaged over a small window (the surface's own slope, not
its faces' normals: a 1 cm TSDF surface's face normals scatter by tens of degrees, decimated they do not).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ...raster import Rasterizer

_MIN_WIN_PX = 3  # the slope window spans at least this many pixels (a central difference needs neighbours)


@dataclass
class PlaneSurface:
    """Per grid pixel (H, W), float32 metres in front of the plane (NaN: no surface there): ``offset``, the
    first surface within the plane's slab; ``front``, the front-most surface near the plane, and
    ``front_cos``, the cosine between its face's normal and the plane's."""

    offset: np.ndarray
    front: np.ndarray
    front_cos: np.ndarray


def cast_surface(points: np.ndarray, n: np.ndarray, raster: Rasterizer, tol: float, front: float,
                 behind: float) -> PlaneSurface:
    """The two casts (module docstring) through the grid ``points`` (H, W, 3) of a plane with normal ``n``."""
    n = np.asarray(n, np.float32)
    pts = np.asarray(points, np.float32)
    back = np.broadcast_to(-n, pts.shape)
    hit = raster.cast_rays(pts + n * np.float32(tol), back)
    offset = np.where(hit.t <= 2 * tol, tol - hit.t, np.nan).astype(np.float32)
    hit = raster.cast_rays(pts + n * np.float32(front), back)
    near = hit.t <= front + behind
    return PlaneSurface(offset, np.where(near, front - hit.t, np.nan).astype(np.float32),
                        np.where(near, hit.normals @ n, np.nan).astype(np.float32))


def flat_surface(offset: np.ndarray, res: float, win: float, max_tilt_deg: float) -> np.ndarray:
    """Pixels with a surface (finite ``offset``) whose tilt against the plane, from the gradient of the
    offsets averaged over ``win`` metres (NaN-aware box mean), is at most ``max_tilt_deg``."""
    seen = np.isfinite(offset)
    if not seen.any():
        return seen
    k = max(_MIN_WIN_PX, int(round(win / res)))
    w = seen.astype(np.float32)
    s = cv2.boxFilter(np.where(seen, offset, 0.0).astype(np.float32), -1, (k, k), normalize=False,
                      borderType=cv2.BORDER_CONSTANT)
    c = cv2.boxFilter(w, -1, (k, k), normalize=False, borderType=cv2.BORDER_CONSTANT)
    mean = np.where(c > 0, s / np.maximum(c, 1e-9), np.nan)
    gy, gx = np.gradient(mean, res)
    with np.errstate(invalid="ignore"):
        return seen & (np.hypot(gx, gy) <= np.tan(np.radians(max_tilt_deg)))
