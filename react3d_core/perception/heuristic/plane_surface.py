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
tolerance, the tilt that of a plane fitted to the hit offsets over a small window (the surface's own slope, not
its faces' normals: a 1 cm TSDF surface's face normals scatter by tens of degrees, decimated they do not).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ...raster import Rasterizer

_MIN_WIN_PX = 3  # the slope window spans at least this many pixels (a fitted slope needs neighbours)
_MIN_DET = 1e-3  # px^4: a window whose pixels lie on one line fixes no slope across it


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
    """Pixels with a surface (finite ``offset``) whose tilt against the plane is at most ``max_tilt_deg``:
    the slope of the plane fitted (least squares) to the offsets within a ``win``-metre window, from the
    window's own pixels only, so it is not flattened at the grid's border or beside holes. Pixels whose
    window holds no two directions (a lone pixel, a one-pixel line) have no slope and are not flat."""
    seen = np.isfinite(offset)
    if not seen.any():
        return seen
    k = max(_MIN_WIN_PX, int(round(win / res)))
    h, w = offset.shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    o = np.where(seen, offset, 0.0).astype(np.float64) / res  # offsets in px: the slope comes out unitless
    wt = seen.astype(np.float64)

    def box(a: np.ndarray) -> np.ndarray:
        return cv2.boxFilter(a, cv2.CV_64F, (k, k), normalize=False, borderType=cv2.BORDER_CONSTANT)

    n = np.maximum(box(wt), 1.0)
    sx, sy, so = box(wt * x), box(wt * y), box(wt * o)
    cxx, cyy, cxy = box(wt * x * x) - sx * sx / n, box(wt * y * y) - sy * sy / n, box(wt * x * y) - sx * sy / n
    cxo, cyo = box(wt * x * o) - sx * so / n, box(wt * y * o) - sy * so / n
    det = cxx * cyy - cxy * cxy
    ok = det > _MIN_DET
    d = np.where(ok, det, 1.0)
    gx, gy = (cyy * cxo - cxy * cyo) / d, (cxx * cyo - cxy * cxo) / d
    return seen & ok & (np.hypot(gx, gy) <= np.tan(np.radians(max_tilt_deg)))
