"""Rectified, occlusion-aware orthophotos of vertical planes, fused over the views that see them.

For every plane an image grid is laid in the plane (u to the right, z up, row 0 on top). Each view
projects the grid into its colour image; a grid pixel is taken from a view only where the view's
face-id buffer (eroded, so occluder outlines are dropped) shows a face of that plane there, so chairs
and tables never paint onto the plane. Colours are divided by the view's mean over the plane
(exposure changes) and fused by the per-pixel median over views (specular highlights move between
views and drop out).

Colour and depth are often not registered (7-Scenes: uncalibrated Kinect colour camera, so the
stated focal length is ~10 % off): before fusing, the colour intrinsics are self-calibrated per scene
— a focal scale and a principal-point shift — by minimising the disagreement between views on the
largest planes. A scan whose colour is registered keeps scale 1, shift 0. Then each view gets its own
correction on top (``view_registration``): colour that is not synchronised with depth is off by a
different amount in every frame.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from ...config.heuristic import CalibrationConfig, OrthoConfig, RegistrationConfig
from ...data.frames import Frame
from ...raster import Rasterizer
from .colour_sampling import ColourCalibration, Points as _Points, nanmedian as _nanmedian, \
    pixel_coords as _pixel_coords, remap_points as _remap_points
from .constants import NEIGHBOURS, RGB
from .planes import Plane
from .view_registration import register_views

_NEAR = 0.1  # m: points closer to the camera than this are at or behind it (no projection)
_WINDOW_STEP = 4  # grid points: a plane's window in a view is found on every this-many-th point, widened by one
_MIN_SAMPLES = 20  # a view with fewer samples of a plane tells nothing about its exposure there
_BEST_GRID = 5  # without pick_spread, views are scored on this many x this many points of a plane


@dataclass
class Orthophoto:
    """Fused colour (H, W, 3 float32, ~1 = the plane's mean brightness) and views per pixel."""

    plane: Plane
    color: np.ndarray
    n_views: np.ndarray
    u0: float
    v_top: float
    res: float
    layer: Orthophoto | None = None  # the same grid fused some way in front of the plane (build_orthophotos)

    @property
    def valid(self) -> np.ndarray:
        return self.n_views > 0

    def to_uv(self, cols: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """In-plane (u, z) of pixel centres (cols, rows)."""
        return (self.u0 + (np.asarray(cols, float) + 0.5) * self.res,
                self.v_top - (np.asarray(rows, float) + 0.5) * self.res)

    def pixels_of(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grid (rows, cols) of world ``points``' feet on the plane, and which of them fall on the grid."""
        h, w = self.n_views.shape
        cols = np.floor((points @ self.plane.u - self.u0) / self.res).astype(int)
        rows = np.floor((self.v_top - points[:, 2]) / self.res).astype(int)
        return rows, cols, (cols >= 0) & (cols < w) & (rows >= 0) & (rows < h)

    def grid_points(self) -> np.ndarray:
        """World points (H, W, 3) of every pixel centre, on the plane."""
        h, w = self.n_views.shape
        cols, rows = np.meshgrid(np.arange(w), np.arange(h))
        return self.plane.to_world(*self.to_uv(cols, rows))


@dataclass
class _View:
    """What one view sees of a plane's grid, cropped to the rows/columns it sees (a view sees only a
    part of a large plane; sampling the rest would be wasted work)."""

    frame: int
    xn: np.ndarray   # normalised image coords (x/z, y/z) of the crop, float32 (h, w, 2)
    ok: np.ndarray   # crop pixels this view sees
    r0: int = 0      # the crop's first row / column in the grid
    c0: int = 0
    edge_px: np.ndarray | None = None  # crop pixels' distance in the colour image to the nearest depth jump (px)

    @staticmethod
    def cropped(frame: int, xn: np.ndarray, ok: np.ndarray, r_off: int = 0, c_off: int = 0,
                edge_px: np.ndarray | None = None) -> "_View":
        """The view cut to the bounding box of ``ok``; (``r_off``, ``c_off``): where ``xn``/``ok`` start in the grid."""
        rows, cols = np.flatnonzero(ok.any(1)), np.flatnonzero(ok.any(0))
        r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        return _View(frame, np.ascontiguousarray(xn[r0:r1, c0:c1]), np.ascontiguousarray(ok[r0:r1, c0:c1]),
                     int(r0) + r_off, int(c0) + c_off,
                     None if edge_px is None else np.ascontiguousarray(edge_px[r0:r1, c0:c1]))

    def every_other(self) -> "_View":
        """The view on the grid's every other row and column (grid pixels with even indices)."""
        lr, lc = self.r0 % 2, self.c0 % 2
        return _View(self.frame, self.xn[lr::2, lc::2], self.ok[lr::2, lc::2], (self.r0 + lr) // 2, (self.c0 + lc) // 2,
                     None if self.edge_px is None else self.edge_px[lr::2, lc::2])

    def paste(self, crop: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        """``crop`` (h, w[, C]) placed in a NaN grid of ``shape``."""
        out = np.full(tuple(shape) + crop.shape[2:], np.nan, np.float32)
        out[self.r0:self.r0 + crop.shape[0], self.c0:self.c0 + crop.shape[1]] = crop
        return out


def _grid(plane: Plane, res: float, margin: float) -> tuple[np.ndarray, float, float]:
    u0, v_top = plane.extent_u[0] - margin, plane.extent_v[1] + margin
    w = int(np.ceil((plane.extent_u[1] - plane.extent_u[0] + 2 * margin) / res))
    h = int(np.ceil((plane.extent_v[1] - plane.extent_v[0] + 2 * margin) / res))
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    return plane.to_world(u0 + (cols + 0.5) * res, v_top - (rows + 0.5) * res).astype(np.float32), u0, v_top


def build_orthophotos(planes: Sequence[Plane], frames: Sequence[Frame], raster: Rasterizer, n_faces: int,
                      read_rgb: Callable[[Frame], np.ndarray], params: OrthoConfig = OrthoConfig(),
                      calibration: CalibrationConfig = CalibrationConfig(),
                      registration: RegistrationConfig = RegistrationConfig(), layer: float = 0.0
                      ) -> tuple[list[Orthophoto], ColourCalibration, dict[int, ColourCalibration]]:
    """Fused orthophoto of each plane, the scene's colour calibration (``calibration``, when enabled) and
    each registered view's own correction by frame index (``registration``, when it has sigmas; see
    module docstring). With ``layer`` > 0 each orthophoto also holds, as ``layer``, the same grid fused that
    far (m) in front of its plane from the same views in the same pass (where a handle standing that far
    proud is painted in its own place by every view)."""
    if not planes or not frames:
        return [], ColourCalibration(), {}
    n_planes = len(planes)
    grids = []
    for p in planes:
        span = max(p.extent_u[1] - p.extent_u[0], p.extent_v[1] - p.extent_v[0]) + 2 * params.margin
        res = max(params.resolution, span / params.max_side_px)
        grids.append((*_grid(p, res, params.margin), res))
    picks = _pick_views(planes, frames, [g[0] for g in grids], params)
    if layer > 0:  # each plane's twin in front of it: the same grid moved along the normal, seen by the same views
        twins = [(g[0] + (layer * p.n).astype(np.float32), *g[1:]) for g, p in zip(grids, planes)]
        planes, grids, picks = list(planes) + [replace(p, d=p.d + layer) for p in planes], grids + twins, picks + picks
    register = calibration.enabled and bool(registration.sigmas_px)
    views: list[list[_View]] = [[] for _ in planes]
    images: dict[int, np.ndarray] = {}
    for fi, f in enumerate(frames):
        which = [i for i in range(len(planes)) if fi in picks[i]]
        if not which:
            continue
        intr = f.intrinsics
        rw, rh = max(1, round(intr.width * params.render_scale)), max(1, round(intr.height * params.render_scale))
        depth = raster.render(intr.scaled(rw, rh).K, f.c2w, rw, rh).depth
        edges = _depth_edges(depth, params.edge_jump)
        usable = _away_from_edges(depth, params.erode_px, params.edge_jump, edges)
        # in colour-image px; only the per-view registration reads it
        edge_dist = _edge_distance(depth, params.edge_jump, edges) / params.render_scale if register else None
        w2c = f.w2c.astype(np.float32)
        K = intr.K
        for i in which:
            window = _window_in_view(grids[i][0], w2c, K, intr.width, intr.height)
            if window is None:
                continue
            r0, r1, c0, c1 = window
            xn, x, y, z, inside = _project(grids[i][0][r0:r1, c0:c1], w2c, K, intr.width, intr.height)
            rx = np.clip(np.round((np.where(inside, x, 0) + 0.5) * params.render_scale - 0.5), 0, rw - 1).astype(np.int32)
            ry = np.clip(np.round((np.where(inside, y, 0) + 0.5) * params.render_scale - 0.5), 0, rh - 1).astype(np.int32)
            # the view sees the plane point when the scan surface there is at the plane's depth
            ok = inside & usable[ry, rx] & (np.abs(depth[ry, rx] - z) < params.depth_tol + params.depth_tol_rel * np.abs(z))
            if ok.sum() >= params.min_view_px:
                views[i].append(_View.cropped(fi, xn, ok, r0, c0, None if edge_dist is None else edge_dist[ry, rx]))
        if any(v and v[-1].frame == fi for v in views):
            images[fi] = read_rgb(f)
    # calibrated and registered on the planes themselves, the layers only follow
    calib = _calibrate(views[:n_planes], frames, images, calibration) if calibration.enabled else ColourCalibration()
    per_view = register_views(*_half_grid_points(views[:n_planes], [g[0].shape[:2] for g in grids[:n_planes]]), frames,
                              images, calib, registration) if register else {}
    out = [_fuse(p, grids[i], views[i], frames, images, per_view, calib) for i, p in enumerate(planes)]
    for o, twin in zip(out, out[n_planes:]):
        o.layer = twin
    return out[:n_planes], calib, per_view


def _fuse(plane: Plane, grid: tuple[np.ndarray, float, float, float], views: list[_View], frames: Sequence[Frame],
          images: dict[int, np.ndarray], per_view: dict[int, ColourCalibration], calib: ColourCalibration) -> Orthophoto:
    """The per-pixel median over ``views`` of one plane's grid (see module docstring)."""
    pts, u0, v_top, res = grid
    stack = [v.paste(_sample(images[v.frame], frames[v.frame], v, per_view.get(v.frame, calib)), pts.shape[:2])
             for v in views]
    if stack:
        st = np.stack(stack)
        n = np.isfinite(st[..., 0]).sum(0)
        color = _nanmedian(st)
    else:
        n, color = np.zeros(pts.shape[:2], np.int32), np.zeros(pts.shape[:2] + (RGB,), np.float32)
    return Orthophoto(plane, color, n.astype(np.int32), u0, v_top, res)


def _half_grid_points(views: list[list[_View]], shapes: list[tuple[int, int]]) -> tuple[list[list[_Points]], list[int]]:
    """Every view's seen points on every other pixel of its plane's grid, and those grids' sizes."""
    out, sizes = [], []
    for vs, (h, w) in zip(views, shapes):
        w2 = (w + 1) // 2
        pts = []
        for v in vs:
            s = v.every_other()
            rr, cc = np.nonzero(s.ok)
            if len(rr):
                pts.append(_Points(v.frame, (rr + s.r0) * w2 + cc + s.c0, s.xn[rr, cc],
                                   None if s.edge_px is None else s.edge_px[rr, cc]))
        out.append(pts)
        sizes.append(((h + 1) // 2) * w2)
    return out, sizes


def _project(pts: np.ndarray, w2c: np.ndarray, K: np.ndarray, width: int, height: int
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """World points (..., 3) into a view: normalised coords (..., 2) float32, pixel x, y, depth z, and
    whether each lands inside the image in front of the camera."""
    pc = pts @ w2c[:3, :3].T + w2c[:3, 3]
    z = pc[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        xn = np.stack([pc[..., 0] / z, pc[..., 1] / z], -1).astype(np.float32)
    x, y = K[0, 0] * xn[..., 0] + K[0, 2], K[1, 1] * xn[..., 1] + K[1, 2]
    inside = (z > _NEAR) & (x >= 0) & (x <= width - 1) & (y >= 0) & (y <= height - 1)
    return xn, x, y, z, inside


def _window_in_view(pts: np.ndarray, w2c: np.ndarray, K: np.ndarray, width: int, height: int,
                    step: int = _WINDOW_STEP) -> tuple[int, int, int, int] | None:
    """Rows r0:r1, columns c0:c1 of the grid ``pts`` (H, W, 3) that can fall inside the image: found on
    every ``step``-th grid point, widened by a step (the plane's visible part is convex, so no run of
    grid points inside the image is missed unless it is thinner than a step). None: none inside."""
    inside = _project(pts[::step, ::step], w2c, K, width, height)[4]
    if not inside.any():
        return None
    rows, cols = np.flatnonzero(inside.any(1)), np.flatnonzero(inside.any(0))
    H, W = pts.shape[:2]
    return (max(0, (rows[0] - 1) * step), min(H, (rows[-1] + 1) * step + 1),
            max(0, (cols[0] - 1) * step), min(W, (cols[-1] + 1) * step + 1))


def _sample(img: np.ndarray, f: Frame, v: _View, c: ColourCalibration, gray: bool = False) -> np.ndarray:
    """The view's colours on its crop of the grid (NaN where unseen), exposure-normalised, under
    calibration ``c``. Only the image window the samples fall in is converted and read."""
    H, W = img.shape[:2]
    x, y = _pixel_coords(v.xn, f, W, H, c)
    inside = v.ok & (x >= 0) & (x <= W - 1) & (y >= 0) & (y <= H - 1)
    nch = 1 if gray or img.ndim == 2 else img.shape[2]
    if inside.sum() < _MIN_SAMPLES:
        return np.full(v.ok.shape + (nch,), np.nan, np.float32)
    xi, yi = x[inside], y[inside]
    x0, y0 = int(np.floor(xi.min())), int(np.floor(yi.min()))
    x1, y1 = min(W, int(np.floor(xi.max())) + 2), min(H, int(np.floor(yi.max())) + 2)
    win = img[y0:y1, x0:x1]
    if gray and win.ndim > 2:  # a colour window
        win = cv2.cvtColor(win, cv2.COLOR_RGB2GRAY)
    col = cv2.remap(win.astype(np.float32, copy=False), np.where(inside, x - x0, -1), np.where(inside, y - y0, -1),
                    cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    if col.ndim == 2:
        col = col[..., None]
    col = col / max(float(col[inside].mean()), 1.0)
    col[~inside] = np.nan
    return col


def _disagreement(views: list[_Points], frames: Sequence[Frame], gray: dict[int, np.ndarray], c: ColourCalibration,
                  n_grid: int, p: CalibrationConfig) -> float:
    """Mean per-pixel variance across views of the exposure-normalised brightness (pixels seen >=
    ``min_views`` times, at least ``min_px`` of them), accumulated with bincount over the seen points only."""
    idx, val = [], []
    for v in views:
        img = gray[v.frame]
        H, W = img.shape[:2]
        x, y = _pixel_coords(v.xn, frames[v.frame], W, H, c)
        inside = (x >= 0) & (x <= W - 1) & (y >= 0) & (y <= H - 1)
        if inside.sum() < _MIN_SAMPLES:
            continue
        col = _remap_points(img, x[inside], y[inside])
        idx.append(v.idx[inside])
        val.append(col / max(float(col.mean()), 1.0))
    if not idx:
        return float("nan")
    i, x = np.concatenate(idx), np.concatenate(val).astype(np.float64)
    n = np.bincount(i, minlength=n_grid)
    many = n >= p.min_views
    if many.sum() < p.min_px:
        return float("nan")
    s1, s2 = np.bincount(i, x, n_grid)[many], np.bincount(i, x * x, n_grid)[many]
    mean = s1 / n[many]
    return float(np.mean(np.maximum(s2 / n[many] - mean * mean, 0.0)))


def _calibrate(views: list[list[_View]], frames: Sequence[Frame], images: dict[int, np.ndarray],
               p: CalibrationConfig) -> ColourCalibration:
    """Coordinate search of focal scale, then shift, then scale again, on the ``planes`` planes seen most
    (<= ``max_views`` views each, every other grid pixel)."""
    seen = [sum(int(v.ok.sum()) for v in vs) for vs in views]
    use: list[tuple[list[_Points], int]] = []
    for i in np.argsort(seen)[::-1][:p.planes]:
        vs = sorted(views[i], key=lambda v: -int(v.ok.sum()))[:p.max_views]
        if len(vs) >= p.min_views:
            sub = [v.every_other() for v in vs]
            width = max(v.c0 + v.ok.shape[1] for v in sub)
            pts = []
            for v in sub:
                rr, cc = np.nonzero(v.ok)
                pts.append(_Points(v.frame, (rr + v.r0) * width + cc + v.c0, v.xn[rr, cc]))
            use.append((pts, max(v.r0 + v.ok.shape[0] for v in sub) * width))
    if not use:
        return ColourCalibration()
    gray = {v.frame: cv2.cvtColor(images[v.frame], cv2.COLOR_RGB2GRAY).astype(np.float32) for vs, _ in use for v in vs}

    def cost(c: ColourCalibration) -> float:
        vals = [_disagreement(vs, frames, gray, c, n_grid, p) for vs, n_grid in use]
        vals = [v for v in vals if np.isfinite(v)]
        return float(np.mean(vals)) if vals else float("inf")

    base = cost(ColourCalibration())
    best, best_cost = ColourCalibration(), base
    lo, hi = p.scale_range
    r = p.shift_range_px
    fine = (-p.fine_shift_px, 0, p.fine_shift_px)
    # a coarse pass over the whole ranges, then a local one around the best (also when the best is
    # still the identity: re-running the coarse grids there only repeats evaluations)
    for step, coarse in (("scale", True), ("shift", True), ("scale", False), ("shift", False)):
        if step == "scale":
            cands = [ColourCalibration(s, best.dx, best.dy) for s in np.linspace(lo, hi, p.scale_steps)] if coarse else \
                [ColourCalibration(best.scale + d, best.dx, best.dy) for d in p.fine_scales]
        else:
            cands = [ColourCalibration(best.scale, best.dx + dx, best.dy + dy)
                     for dx in np.linspace(-r, r, p.shift_steps) for dy in np.linspace(-r, r, p.shift_steps)] if coarse else \
                [ColourCalibration(best.scale, best.dx + dx, best.dy + dy) for dx in fine for dy in fine if dx or dy]
        for c in cands:
            v = cost(c)
            if v < best_cost:
                best, best_cost = c, v
    if not np.isfinite(base) or best_cost > (1 - p.min_gain) * base:
        return ColourCalibration(before=base, after=base)
    return ColourCalibration(best.scale, best.dx, best.dy, base, best_cost)


def _depth_edges(depth: np.ndarray, jump: float) -> np.ndarray:
    """Pixels at a depth jump over ``jump`` (3x3 max - min) or without a surface."""
    d = np.where(depth > 0, depth, 0.0).astype(np.float32)
    return ((cv2.dilate(d, NEIGHBOURS) - cv2.erode(d, NEIGHBOURS)) > jump) | (d <= 0)


def _edge_distance(depth: np.ndarray, jump: float, edge: np.ndarray | None = None) -> np.ndarray:
    """Per pixel, the distance (px) to the nearest depth jump over ``jump`` or miss: how far a blur may
    reach before it mixes in a surface at another depth (whose place in the image moves with the view).
    ``edge``: those pixels when already found (``_depth_edges``)."""
    edge = _depth_edges(depth, jump) if edge is None else edge
    dist = cv2.distanceTransform((~edge).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    return np.minimum(dist, float(max(depth.shape)))  # no jump at all: the image's size, not FLT_MAX


def _away_from_edges(depth: np.ndarray, px: int, jump: float, edge: np.ndarray | None = None) -> np.ndarray:
    """Pixels with a surface whose (2px+1)² neighbourhood has no depth jump over ``jump`` and no miss.
    ``edge``: those jumps and misses when already found (``_depth_edges``)."""
    edge = _depth_edges(depth, jump) if edge is None else edge
    if px > 0:
        edge = cv2.dilate(edge.astype(np.uint8), np.ones((2 * px + 1, 2 * px + 1), np.uint8)).astype(bool)
    return ~edge


def project_into_views(points: np.ndarray, w2cs: np.ndarray, Ks: np.ndarray, size: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Pixel coordinates ``x``, ``y`` and depth ``z`` (F, S) of world ``points`` (S, 3) in F pinhole views
    (world-to-camera ``w2cs`` (F, 4, 4), intrinsics ``Ks`` (F, 3, 3), image ``size`` (F, 2) as w, h), and
    whether each lies in front of the camera (beyond ``_NEAR``) and inside its image."""
    pc = np.einsum("fij,sj->fsi", w2cs[:, :3, :3], points) + w2cs[:, None, :3, 3]
    z = pc[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = Ks[:, None, 0, 0] * pc[..., 0] / z + Ks[:, None, 0, 2]
        y = Ks[:, None, 1, 1] * pc[..., 1] / z + Ks[:, None, 1, 2]
    inside = (z > _NEAR) & (x >= 0) & (x < size[:, None, 0]) & (y >= 0) & (y < size[:, None, 1])
    return x, y, z, inside


def _pick_views(planes: Sequence[Plane], frames: Sequence[Frame], grids: list[np.ndarray], p: OrthoConfig) -> list[set[int]]:
    """Per plane, up to ``max_views`` frames chosen for coverage, sharpness and diversity, on a
    ``pick_samples`` x ``pick_samples`` sample of the plane: each sample wants ``pick_need`` views; a frame is
    worth the sum, over the samples that still want views and that it sees (in front, inside the image, at
    least ``min_cos`` to the normal), of its sharpness there (cosine over distance: a near, frontal view
    puts more pixels on the plane and misregisters it by fewer millimetres); the best is taken, then every
    frame within ``pick_sep`` metres and ``pick_sep_deg`` of it is passed over (a dense capture's next
    frames add nothing new, and their colour is off the same way). So the views fused depend on where the
    cameras were, not on how densely the walk was sampled. Without ``pick_spread``: the ``max_views`` frames
    with the largest sum of cosines over a 5 x 5 sample (those seeing most of the plane, frontally)."""
    centers = np.array([f.c2w[:3, 3] for f in frames])
    axes = np.array([f.c2w[:3, 2] for f in frames])
    w2cs = np.array([f.w2c for f in frames])
    Ks = np.array([f.intrinsics.K for f in frames])
    size = np.array([(f.intrinsics.width, f.intrinsics.height) for f in frames], float)
    cos_sep = np.cos(np.radians(p.pick_sep_deg))
    out = []
    for pl, pts in zip(planes, grids):
        h, w = pts.shape[:2]
        k = p.pick_samples if p.pick_spread else _BEST_GRID
        sample = pts[np.ix_(np.linspace(0, h - 1, k).astype(int), np.linspace(0, w - 1, k).astype(int))].reshape(-1, pts.shape[-1])
        x, y, z, inside = project_into_views(sample, w2cs, Ks, size)
        ray = sample[None] - centers[:, None]
        dist = np.maximum(np.linalg.norm(ray, axis=-1), _NEAR)
        cos = -(ray @ pl.n) / dist
        if not p.pick_spread:
            score = (cos * (inside & (cos >= p.min_cos))).sum(1)
            out.append({int(i) for i in np.argsort(-score)[:p.max_views] if score[i] > 0})
            continue
        sharp = np.where(inside & (cos >= p.min_cos), cos / dist, 0.0)  # (frames, samples)
        need = np.full(sharp.shape[1], p.pick_need)
        alive = sharp.any(1)
        chosen: set[int] = set()
        while len(chosen) < p.max_views and alive.any():
            value = np.where(alive, (sharp * (need > 0)).sum(1), 0.0)
            if value.max() <= 0:
                break
            i = int(np.argmax(value))
            chosen.add(i)
            need -= sharp[i] > 0
            alive &= ~((np.linalg.norm(centers - centers[i], axis=1) < p.pick_sep) & (axes @ axes[i] > cos_sep))
            alive[i] = False
        out.append(chosen)
    return out
