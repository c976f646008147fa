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
largest planes. A scan whose colour is registered keeps scale 1, shift 0.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ...config.perception import HeuristicConfig
from ...data.frames import Frame
from ...raster import Rasterizer
from .planes import Plane

_H = HeuristicConfig()  # defaults and descriptions live in the config (perception.heuristic.ortho_*, calib_*)


@dataclass(frozen=True)
class OrthoParams:
    """Orthophoto parameters, built from ``HeuristicConfig`` by ``image_fronts.params_from_config``."""

    resolution: float = _H.ortho_resolution      # m per grid pixel
    max_side_px: int = _H.ortho_max_side_px      # coarser grid for very large planes
    max_views: int = _H.max_views                # views per plane, best first
    min_cos: float = _H.ortho_min_cos            # views more grazing than this are not used
    render_scale: float = _H.ortho_render_scale  # face-id buffer size relative to the colour image
    erode_px: int = _H.ortho_erode_px            # depth-buffer pixels kept away from depth jumps (occluder outlines)
    edge_jump: float = _H.ortho_edge_jump        # m: a depth jump between neighbouring pixels that marks an outline
    depth_tol: float = _H.ortho_depth_tol        # m (+1 % of the distance): a plane point is seen when the scan is there
    margin: float = _H.ortho_margin              # m of grid around a plane's extent
    calibrate: bool = _H.calibrate_colour        # self-calibrate colour focal scale / principal-point shift
    scale_range: tuple[float, float] = _H.calib_scale_range
    shift_range_px: float = _H.calib_shift_range_px  # at 640 px image width
    min_gain: float = _H.calib_min_gain          # a calibration must cut the disagreement by this fraction to be used


@dataclass
class Orthophoto:
    """Fused colour (H, W, 3 float32, ~1 = the plane's mean brightness) and views per pixel."""

    plane: Plane
    color: np.ndarray
    n_views: np.ndarray
    u0: float
    v_top: float
    res: float
    spread: np.ndarray | None = None  # per-pixel median |view - fused| brightness: high where things protrude (parallax)

    @property
    def valid(self) -> np.ndarray:
        return self.n_views > 0

    def to_uv(self, cols: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """In-plane (u, z) of pixel centres (cols, rows)."""
        return (self.u0 + (np.asarray(cols, float) + 0.5) * self.res,
                self.v_top - (np.asarray(rows, float) + 0.5) * self.res)


@dataclass(frozen=True)
class ColourCalibration:
    """Correction of the colour intrinsics: fx, fy scaled by ``scale``; cx, cy shifted by (dx, dy)
    pixels at 640 px width; disagreement between views before and after."""

    scale: float = 1.0
    dx: float = 0.0
    dy: float = 0.0
    before: float = 0.0
    after: float = 0.0


@dataclass
class _View:
    frame: int
    xn: np.ndarray   # normalised image coords (x/z, y/z) of the grid, float32 (H, W, 2)
    ok: np.ndarray   # grid pixels this view sees


def _grid(plane: Plane, res: float, margin: float) -> tuple[np.ndarray, float, float]:
    u0, v_top = plane.extent_u[0] - margin, plane.extent_v[1] + margin
    w = int(np.ceil((plane.extent_u[1] - plane.extent_u[0] + 2 * margin) / res))
    h = int(np.ceil((plane.extent_v[1] - plane.extent_v[0] + 2 * margin) / res))
    cols, rows = np.meshgrid(np.arange(w), np.arange(h))
    return plane.to_world(u0 + (cols + 0.5) * res, v_top - (rows + 0.5) * res).astype(np.float32), u0, v_top


def build_orthophotos(planes: Sequence[Plane], frames: Sequence[Frame], raster: Rasterizer, n_faces: int,
                      read_rgb: Callable[[Frame], np.ndarray], params: OrthoParams = OrthoParams()
                      ) -> tuple[list[Orthophoto], ColourCalibration]:
    """Fused orthophoto of each plane and the colour calibration used (see module docstring)."""
    if not planes or not frames:
        return [], ColourCalibration()
    grids = []
    for p in planes:
        span = max(p.extent_u[1] - p.extent_u[0], p.extent_v[1] - p.extent_v[0]) + 2 * params.margin
        res = max(params.resolution, span / params.max_side_px)
        grids.append((*_grid(p, res, params.margin), res))
    picks = _pick_views(planes, frames, [g[0] for g in grids], params.min_cos, params.max_views)
    views: list[list[_View]] = [[] for _ in planes]
    images: dict[int, np.ndarray] = {}
    for fi, f in enumerate(frames):
        which = [i for i in range(len(planes)) if fi in picks[i]]
        if not which:
            continue
        intr = f.intrinsics
        rw, rh = max(1, round(intr.width * params.render_scale)), max(1, round(intr.height * params.render_scale))
        depth = raster.render(intr.scaled(rw, rh).K, f.c2w, rw, rh).depth
        usable = _away_from_edges(depth, params.erode_px, params.edge_jump)
        w2c = f.w2c.astype(np.float32)
        K = intr.K
        for i in which:
            pc = grids[i][0] @ w2c[:3, :3].T + w2c[:3, 3]
            z = pc[..., 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                xn = np.stack([pc[..., 0] / z, pc[..., 1] / z], -1).astype(np.float32)
            x, y = K[0, 0] * xn[..., 0] + K[0, 2], K[1, 1] * xn[..., 1] + K[1, 2]
            inside = (z > 0.1) & (x >= 0) & (x <= intr.width - 1) & (y >= 0) & (y <= intr.height - 1)
            rx = np.clip(np.round((np.where(inside, x, 0) + 0.5) * params.render_scale - 0.5), 0, rw - 1).astype(np.int32)
            ry = np.clip(np.round((np.where(inside, y, 0) + 0.5) * params.render_scale - 0.5), 0, rh - 1).astype(np.int32)
            # the view sees the plane point when the scan surface there is at the plane's depth
            ok = inside & usable[ry, rx] & (np.abs(depth[ry, rx] - z) < params.depth_tol + 0.01 * np.abs(z))
            if ok.sum() >= 50:
                views[i].append(_View(fi, xn, ok))
        if any(v and v[-1].frame == fi for v in views):
            images[fi] = read_rgb(f)
    calib = _calibrate(views, frames, images, params) if params.calibrate else ColourCalibration()
    out = []
    for i, p in enumerate(planes):
        pts, u0, v_top, res = grids[i]
        stack = [_sample(images[v.frame], frames[v.frame], v, calib) for v in views[i]]
        if stack:
            st = np.stack(stack)
            n = np.isfinite(st[..., 0]).sum(0)
            color = _nanmedian(st)
            spread = _nanmedian(np.abs(st.mean(-1) - color.mean(-1)[None]))
        else:
            n, color = np.zeros(pts.shape[:2], np.int32), np.zeros(pts.shape[:2] + (3,), np.float32)
            spread = np.zeros(pts.shape[:2], np.float32)
        out.append(Orthophoto(p, color, n.astype(np.int32), u0, v_top, res, spread))
    return out, calib


def _sample(img: np.ndarray, f: Frame, v: _View, c: ColourCalibration, gray: bool = False) -> np.ndarray:
    """The view's colours on the grid (NaN where unseen), exposure-normalised, under calibration ``c``."""
    H, W = img.shape[:2]
    intr = f.intrinsics if (f.intrinsics.width, f.intrinsics.height) == (W, H) else f.intrinsics.scaled(W, H)
    s = W / 640.0
    x = (c.scale * intr.fx * v.xn[..., 0] + intr.cx + c.dx * s).astype(np.float32)
    y = (c.scale * intr.fy * v.xn[..., 1] + intr.cy + c.dy * s).astype(np.float32)
    src = (img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)) if gray else img
    col = cv2.remap(src.astype(np.float32), np.where(v.ok, x, -1), np.where(v.ok, y, -1), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    inside = v.ok & (x >= 0) & (x <= W - 1) & (y >= 0) & (y <= H - 1)
    if gray:
        col = col[..., None]
    if inside.sum() < 20:
        return np.full(col.shape, np.nan, np.float32)
    col = col / max(float(col[inside].mean()), 1.0)
    col[~inside] = np.nan
    return col


def _disagreement(views: list[_View], frames: Sequence[Frame], images: dict[int, np.ndarray], c: ColourCalibration) -> float:
    """Mean per-pixel variance across views of the exposure-normalised brightness (pixels seen >= 3 times)."""
    st = np.stack([_sample(images[v.frame], frames[v.frame], v, c, gray=True)[..., 0] for v in views])
    n = np.isfinite(st).sum(0)
    if (n >= 3).sum() < 100:
        return float("nan")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return float(np.nanmean(np.nanvar(st, 0)[n >= 3]))


def _calibrate(views: list[list[_View]], frames: Sequence[Frame], images: dict[int, np.ndarray],
               p: OrthoParams) -> ColourCalibration:
    """Coordinate search of focal scale, then shift, then scale again, on the two planes seen most
    (<= 12 views each, every other grid pixel)."""
    seen = [sum(int(v.ok.sum()) for v in vs) for vs in views]
    use = []
    for i in np.argsort(seen)[::-1][:2]:
        vs = sorted(views[i], key=lambda v: -int(v.ok.sum()))[:12]
        if len(vs) >= 3:
            use.append([_View(v.frame, v.xn[::2, ::2], v.ok[::2, ::2]) for v in vs])
    if not use:
        return ColourCalibration()
    gray = {v.frame: cv2.cvtColor(images[v.frame], cv2.COLOR_RGB2GRAY) for vs in use for v in vs}
    images = gray  # every cost evaluation samples brightness only: convert each frame once

    def cost(c: ColourCalibration) -> float:
        vals = [_disagreement(vs, frames, images, c) for vs in use]
        vals = [v for v in vals if np.isfinite(v)]
        return float(np.mean(vals)) if vals else float("inf")

    base = cost(ColourCalibration())
    best, best_cost = ColourCalibration(), base
    lo, hi = p.scale_range
    for step in ("scale", "shift", "scale", "shift"):
        if step == "scale":
            cands = [ColourCalibration(s, best.dx, best.dy) for s in np.linspace(lo, hi, 15)] if best.scale == 1.0 else \
                [ColourCalibration(best.scale + d, best.dx, best.dy) for d in (-0.02, -0.01, 0.01, 0.02)]
        else:
            r = p.shift_range_px
            cands = [ColourCalibration(best.scale, best.dx + dx, best.dy + dy)
                     for dx in np.linspace(-r, r, 5) for dy in np.linspace(-r, r, 5)] if step == "shift" and best.dx == 0 and best.dy == 0 else \
                [ColourCalibration(best.scale, best.dx + dx, best.dy + dy) for dx in (-3, 0, 3) for dy in (-3, 0, 3)]
        for c in cands:
            v = cost(c)
            if v < best_cost:
                best, best_cost = c, v
    if not np.isfinite(base) or best_cost > (1 - p.min_gain) * base:
        return ColourCalibration(before=base, after=base)
    return ColourCalibration(best.scale, best.dx, best.dy, base, best_cost)


def _nanmedian(stack: np.ndarray) -> np.ndarray:
    """Per-pixel median over views (axis 0) ignoring NaN, 0 where no view. Sort-based, one channel
    at a time (numpy's nanmedian is ~10x slower and copies the whole stack)."""
    out = np.zeros(stack.shape[1:], np.float32)
    chans = [None] if stack.ndim == 3 else range(stack.shape[-1])
    for c in chans:
        a = stack if c is None else stack[..., c]
        a = np.where(np.isfinite(a), a, np.inf).astype(np.float32)
        a.sort(axis=0)
        n = np.isfinite(a).sum(0)
        lo = np.take_along_axis(a, np.maximum((n - 1) // 2, 0)[None], 0)[0]
        hi = np.take_along_axis(a, np.maximum(n // 2, 0)[None], 0)[0]
        med = np.where(n > 0, 0.5 * (lo + hi), 0.0)
        if c is None:
            out = med.astype(np.float32)
        else:
            out[..., c] = med
    return out


def _away_from_edges(depth: np.ndarray, px: int, jump: float) -> np.ndarray:
    """Pixels with a surface whose (2px+1)² neighbourhood has no depth jump over ``jump`` and no miss."""
    d = np.where(depth > 0, depth, 0.0).astype(np.float32)
    k = np.ones((3, 3), np.uint8)
    edge = ((cv2.dilate(d, k) - cv2.erode(d, k)) > jump) | (d <= 0)
    if px > 0:
        edge = cv2.dilate(edge.astype(np.uint8), np.ones((2 * px + 1, 2 * px + 1), np.uint8)).astype(bool)
    return ~edge


def _pick_views(planes: Sequence[Plane], frames: Sequence[Frame], grids: list[np.ndarray], min_cos: float,
                max_views: int) -> list[set[int]]:
    """Per plane, the best ``max_views`` frames, scored on a 25-point sample of the plane (in front of
    the camera, inside the image) times the cosine between view ray and plane normal."""
    centers = np.array([f.c2w[:3, 3] for f in frames])
    w2cs = np.array([f.w2c for f in frames])
    Ks = np.array([f.intrinsics.K for f in frames])
    size = np.array([(f.intrinsics.width, f.intrinsics.height) for f in frames], float)
    out = []
    for p, pts in zip(planes, grids):
        h, w = pts.shape[:2]
        sample = pts[np.ix_(np.linspace(0, h - 1, 5).astype(int), np.linspace(0, w - 1, 5).astype(int))].reshape(-1, 3)
        pc = np.einsum("fij,sj->fsi", w2cs[:, :3, :3], sample) + w2cs[:, None, :3, 3]
        z = pc[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            x = Ks[:, None, 0, 0] * pc[..., 0] / z + Ks[:, None, 0, 2]
            y = Ks[:, None, 1, 1] * pc[..., 1] / z + Ks[:, None, 1, 2]
        inside = (z > 0.1) & (x >= 0) & (x < size[:, None, 0]) & (y >= 0) & (y < size[:, None, 1])
        ray = sample[None] - centers[:, None]
        cos = -(ray @ p.n) / np.maximum(np.linalg.norm(ray, axis=-1), 1e-9)
        scores = (cos * (inside & (cos >= min_cos))).sum(1)
        order = np.argsort(-scores)
        out.append({int(i) for i in order[:max_views] if scores[i] > 0})
    return out
