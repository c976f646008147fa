"""Per-view registration of the colour images onto the scan, before the orthophotos are fused.

Why: in RGB-D scans whose colour camera is neither registered nor synchronised with the depth camera
(7-Scenes: the poses are the depth camera's), the colour image of each frame differs from the pose
projection by its own scale (0.85-0.99) and shift (up to ~25 px at the image centre), measured on
RedKitchen's labelled frames. One calibration per scene leaves the views of a plane offset against
each other by several seam widths, so the fused median smears the seams away, and which seams
survive depends on which frames were picked.

How: every view gets its own correction of the colour intrinsics (focal scale and principal-point
shift; ``ColourCalibration``). Starting from the scene calibration, each view is moved onto the
per-pixel median of all views (on every other orthophoto pixel) by Gauss-Newton steps, coarse to
fine: the images are blurred at decreasing sigmas so that large offsets are caught first and the
median sharpens as the views come together. The signal is band-passed log brightness (exposure is an
offset in log; the band-pass drops smooth shading, which differs between views), and points whose blur
reaches a depth jump are left out (the surface behind an outline moves with the view). Huber weights
keep specular highlights from pulling; a Gaussian prior towards the scene calibration, with the data
counted per blur-sized cell, holds what a view's texture does not determine (a plane with only
vertical lines says nothing about the vertical shift). After every round the corrections lose their
median drift, and at the end a view keeps its correction only when it fits clearly better than the
scene calibration. A scan whose colour is registered ends where it started (its views already agree).
Opt-in (``perception.heuristic.registration.sigmas_px``); docs/perception.md has what it gains and costs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from ...config.heuristic import RegistrationConfig
from ...data.frames import Frame
from .colour_sampling import ColourCalibration, Points, nanmedian, pixel_coords, remap_points
from .constants import COLOUR_NDIM, MAD_SIGMA, REFERENCE_WIDTH_PX

_LOG_OFFSET = 8.0  # grey levels added before the log: dark pixels' noise must not blow up
_SOBEL = 3  # Sobel kernel size ...
_SOBEL_SUM = 8.0  # ... whose weights sum to 8 times the gradient
_MIN_SCALE = 1e-4  # floor of the residuals' robust scale (a view that matches exactly)
_HUBER_K = 1.345  # Huber's constant: 95 % efficiency on normal residuals
_CELL_HASH = 100_003  # a prime above any cell column count: (row, column) -> one integer


@dataclass
class _Seen:
    """What one frame sees of all planes: per point its plane, grid index and normalised image coords."""

    plane: np.ndarray  # (N,) int32
    idx: np.ndarray    # (N,) int64 flat index into the plane's sub-sampled grid
    xn: np.ndarray     # (N, 2) float32
    edge_px: np.ndarray  # (N,) distance to the nearest depth jump in the image (px)
    segments: np.ndarray  # (P,) plane ids present


def register_views(planes_points: Sequence[Sequence[Points]], grid_sizes: Sequence[int], frames: Sequence[Frame],
                   images: dict[int, np.ndarray], calib: ColourCalibration,
                   p: RegistrationConfig = RegistrationConfig()) -> dict[int, ColourCalibration]:
    """Each frame's colour correction (frames not registered keep ``calib``). ``planes_points[i]``:
    every view's seen points of plane i's sub-sampled grid (``grid_sizes[i]`` pixels)."""
    seen = _by_frame(planes_points)
    cur = {f: calib for f in seen}
    if not p.sigmas_px or len(seen) < 2:
        return cur
    logs = {f: np.log(_gray(images[f]) + _LOG_OFFSET) for f in seen}
    for sigma in p.sigmas_px:
        blur, grads = {}, {}
        for f, g in logs.items():
            s = sigma * g.shape[1] / REFERENCE_WIDTH_PX
            b = cv2.GaussianBlur(g, (0, 0), s)
            if p.band > 0:
                b = b - cv2.GaussianBlur(g, (0, 0), p.band * s)
            blur[f] = b
            grads[f] = (cv2.Sobel(b, cv2.CV_32F, 1, 0, ksize=_SOBEL) / _SOBEL_SUM,
                        cv2.Sobel(b, cv2.CV_32F, 0, 1, ksize=_SOBEL) / _SOBEL_SUM)
        for _ in range(p.rounds):
            lv = (p.reach * max(p.band, 1.0) * sigma, p.band <= 0)
            refs = _medians(seen, frames, blur, cur, grid_sizes, p.min_views, lv)
            for f, pts in seen.items():
                cur[f] = _gauss_newton(pts, frames[f], blur[f], grads[f], refs, cur[f], calib, sigma, p, lv)
            cur = _recentred(cur, calib)
    # last word to the scene calibration: a view keeps its own correction only when that fits the final
    # (sharpest) median clearly better (a view that saw little texture may have wandered off)
    refs = _medians(seen, frames, blur, cur, grid_sizes, p.min_views, lv)
    for f, pts in seen.items():
        if not _clearly_better(pts, frames[f], blur[f], refs, cur[f], calib, p, lv):
            cur[f] = calib
    return cur


def _clearly_better(pts: "_Seen", f: Frame, img: np.ndarray, refs: list[np.ndarray], c: ColourCalibration,
                    base: ColourCalibration, p: RegistrationConfig, lv: tuple[float, bool]) -> bool:
    """Whether ``c`` fits the medians ``refs`` by ``p.min_gain`` better than ``base`` (robust cost on the
    points seen under both)."""
    target = _targets(pts, refs)
    a, ok_a = _sample(pts, f, img, c, lv)[:2]
    b, ok_b = _sample(pts, f, img, base, lv)[:2]
    costs = _costs(a, ok_a, b, ok_b, target, p.min_points)
    return costs is not None and costs[0] < (1 - p.min_gain) * costs[1]


def _costs(new: np.ndarray, ok_new: np.ndarray, old: np.ndarray, ok_old: np.ndarray, target: np.ndarray,
           min_points: int) -> tuple[float, float] | None:
    """Robust costs (new, old) against ``target`` on the points both see, at the old residuals' scale;
    None when fewer than ``min_points`` are seen by both."""
    both = np.isfinite(target) & ok_new & ok_old
    if both.sum() < min_points:
        return None
    s = _mad_scale(old[both] - target[both])
    return _huber(new[both] - target[both], s)[0], _huber(old[both] - target[both], s)[0]


def _targets(pts: "_Seen", refs: list[np.ndarray]) -> np.ndarray:
    """The medians at a frame's points (NaN where there is none)."""
    offs = np.cumsum([0] + [len(r) for r in refs])[:-1]
    return np.concatenate(refs)[offs[pts.plane] + pts.idx]


def _recentred(cur: dict[int, ColourCalibration], calib: ColourCalibration) -> dict[int, ColourCalibration]:
    """The corrections less their median deviation from the scene calibration: the views may all drift
    together onto their own consensus (a common scale or shift changes no disagreement), but the
    colour must stay where the scene calibration put it against the mesh. The median, so that a few
    views that wandered off do not move the others."""
    th = np.array([_theta(c) for c in cur.values()])
    drift = np.median(th, 0) - _theta(calib)
    return {f: _with(c, t) for (f, c), t in zip(cur.items(), th - drift)}


def _gray(img: np.ndarray) -> np.ndarray:
    g = cv2.cvtColor(img, cv2.COLOR_RGB2GRAY) if img.ndim == COLOUR_NDIM else img
    return g.astype(np.float32)


def _by_frame(planes_points: Sequence[Sequence[Points]]) -> dict[int, _Seen]:
    parts: dict[int, list[tuple[int, Points]]] = {}
    for i, pts in enumerate(planes_points):
        for v in pts:
            parts.setdefault(v.frame, []).append((i, v))
    out = {}
    for f, lst in parts.items():
        out[f] = _Seen(np.concatenate([np.full(len(v.idx), i, np.int32) for i, v in lst]),
                       np.concatenate([v.idx for _, v in lst]).astype(np.int64),
                       np.concatenate([v.xn for _, v in lst]).astype(np.float32),
                       np.concatenate([np.full(len(v.idx), np.inf, np.float32) if v.edge_px is None else v.edge_px
                                       for _, v in lst]).astype(np.float32),
                       np.array(sorted({i for i, _ in lst}), np.int32))
    return out


def _sample(pts: _Seen, f: Frame, img: np.ndarray, c: ColourCalibration, lv: tuple[float, bool] = (0.0, False)
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The signal at the frame's points under ``c`` (NaN where not used), whether used, and the pixel
    coords. ``lv`` = (reach, centre): points nearer than ``reach`` px (at 640 px width) to a depth jump
    are not used (the blur there mixes in a surface whose place moves with the view); ``centre``: less
    the plane's mean (log brightness blurred, not band-passed)."""
    reach, centre = lv
    H, W = img.shape[:2]
    x, y = pixel_coords(pts.xn, f, W, H, c)
    inside = (x >= 1) & (x <= W - 2) & (y >= 1) & (y <= H - 2) & (pts.edge_px >= reach * W / REFERENCE_WIDTH_PX)
    val = np.full(len(x), np.nan, np.float32)
    val[inside] = remap_points(img, x[inside], y[inside])
    if centre:
        val = _less_plane_means(val, pts.plane)
    return val, inside, x, y


def _less_plane_means(val: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """Values less the mean of their plane's finite values (log brightness: an exposure change is an offset)."""
    ok = np.isfinite(val)
    n = np.bincount(plane[ok], minlength=plane.max() + 1)
    s = np.bincount(plane[ok], val[ok], minlength=plane.max() + 1)
    return val - (s / np.maximum(n, 1))[plane].astype(np.float32)


def _medians(seen: dict[int, _Seen], frames: Sequence[Frame], imgs: dict[int, np.ndarray],
             cur: dict[int, ColourCalibration], grid_sizes: Sequence[int], min_views: int,
             lv: tuple[float, bool]) -> list[np.ndarray]:
    """Per plane, the median over views of the signal per grid pixel (NaN where fewer than
    ``min_views`` views)."""
    per_plane: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in grid_sizes]
    for f, pts in seen.items():
        val = _sample(pts, frames[f], imgs[f], cur[f], lv)[0]
        for i in pts.segments:
            m = pts.plane == i
            per_plane[i].append((pts.idx[m], val[m]))
    out = []
    for i, lst in enumerate(per_plane):
        ref = np.full(grid_sizes[i], np.nan, np.float32)
        if len(lst) >= min_views:
            stack = np.full((len(lst), 1, grid_sizes[i]), np.nan, np.float32)
            for k, (idx, val) in enumerate(lst):
                stack[k, 0, idx] = val
            n = np.isfinite(stack[:, 0]).sum(0)
            med = nanmedian(stack)[0]
            ref[n >= min_views] = med[n >= min_views]
        out.append(ref)
    return out


def _theta(c: ColourCalibration) -> np.ndarray:
    return np.array([c.scale, c.dx, c.dy])


def _with(c: ColourCalibration, th: np.ndarray) -> ColourCalibration:
    return replace(c, scale=float(th[0]), dx=float(th[1]), dy=float(th[2]))


def _mad_scale(e: np.ndarray) -> float:
    return max(MAD_SIGMA * float(np.median(np.abs(e))), _MIN_SCALE)


def _huber(e: np.ndarray, s: float) -> tuple[float, np.ndarray]:
    """Mean Huber cost of residuals ``e`` at scale ``s`` (in units of s²) and the Huber weights."""
    k = _HUBER_K * s
    a = np.abs(e)
    w = np.where(a <= k, 1.0, k / np.maximum(a, 1e-12))
    cost = np.where(a <= k, 0.5 * a * a, k * (a - 0.5 * k))
    return float(cost.mean()) / (s * s), w


def _gauss_newton(pts: _Seen, f: Frame, img: np.ndarray, grads: tuple[np.ndarray, np.ndarray], refs: list[np.ndarray],
                  c: ColourCalibration, prior: ColourCalibration, sigma: float, p: RegistrationConfig,
                  lv: tuple[float, bool]) -> ColourCalibration:
    """``c`` moved onto the medians ``refs`` by up to ``p.iters`` Gauss-Newton steps; kept when the
    robust disagreement (on the points seen before and after) does not drop."""
    target = _targets(pts, refs)
    use = np.isfinite(target)
    if use.sum() < p.min_points:
        return c
    H, W = img.shape[:2]
    intr = f.intrinsics if (f.intrinsics.width, f.intrinsics.height) == (W, H) else f.intrinsics.scaled(W, H)
    k = W / REFERENCE_WIDTH_PX
    prior_std = np.array([p.prior_scale, p.prior_shift_px, p.prior_shift_px])
    P = np.diag(1.0 / prior_std ** 2)
    t0 = _theta(prior)

    def evaluate(cc: ColourCalibration):
        val, inside, x, y = _sample(pts, f, img, cc, lv)
        ok = use & inside & np.isfinite(val)
        return val, ok, x, y

    val, ok, x, y = evaluate(c)
    if ok.sum() < p.min_points:
        return c
    start_ok, start_val = ok, val
    th = _theta(c)
    for _ in range(p.iters):
        e = (val - target)[ok]
        s2 = _mad_scale(e) ** 2
        w = _huber(e, s2 ** 0.5)[1]
        gx = remap_points(grads[0], x[ok], y[ok])
        gy = remap_points(grads[1], x[ok], y[ok])
        xn, yn = pts.xn[ok, 0], pts.xn[ok, 1]
        J = np.stack([gx * intr.fx * xn + gy * intr.fy * yn, gx * k, gy * k], 1)  # d(signal)/d(theta)
        # neighbouring samples of a blurred image are not independent: the data count as many
        # observations as there are blur-sized (2 sigma) cells under the points, so that the prior
        # still holds a view whose texture leaves a direction open
        cell = 2.0 * sigma * k
        n_cells = len(np.unique(np.floor(x[ok] / cell).astype(np.int64) * _CELL_HASH + np.floor(y[ok] / cell).astype(np.int64)))
        weight = n_cells / (ok.sum() * s2)
        Jw = J * w[:, None]
        A = weight * (Jw.T @ J) + P
        b = weight * (Jw.T @ e) + P @ (th - t0)
        try:
            step = -np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            break
        lim = np.array([p.max_scale_step, sigma, sigma])
        step = np.clip(step, -lim, lim)
        th = th + step
        val, ok, x, y = evaluate(_with(c, th))
        if ok.sum() < p.min_points:
            return c
        if np.abs(step[1:]).max() < p.converged_shift_px and abs(step[0]) < p.converged_scale:
            break
    costs = _costs(val, ok, start_val, start_ok, target, p.min_points)
    return _with(c, th) if costs is not None and costs[0] < costs[1] else c
