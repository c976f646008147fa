"""Seam evidence from straight line segments that a detector finds in the colour frames.

A seam between two fronts is a straight line in every photo that sees it. A line-segment detector gives, per
frame, segments in pixels: OpenCV's LSD by default (classic_lines.py, no weights) or the learned M-LSD (run
outside the core: react3d_models/line_segments.py); they reach this module as plain arrays. Each segment is carried onto a plane by ray–plane intersection and kept only
where the scan surface seen along the ray is that plane, a few pixels to either side too (the edge of a
chair in front of a cabinet is not on the cabinet; colour and depth may be misregistered by a few pixels).
What is left is drawn into the plane's orthophoto grid as vertical or horizontal line evidence, and a grid
pixel's support is the number of views whose segments pass through it: a seam is where several views
agree, while edges of occluders, reflections and texture move between views. ``front_cells`` cuts cells
at lines that enough views support (``perception.heuristic.lines``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ...config.heuristic import HeuristicConfig, LineConfig, OrthoConfig
from ...data.frames import Frame
from ...raster import Rasterizer
from .colour_sampling import ColourCalibration
from .constants import REFERENCE_WIDTH_PX
from .orthophoto import Orthophoto, project_into_views

_NEAR = 0.1  # m: plane points closer to the camera than this are at or behind it
_SAMPLES_PER_PX = 2  # a segment is followed at half a grid pixel on the plane ...
_MAX_SAMPLES = 4096  # ... with at most this many samples (a segment seen nearly edge-on spans metres)
_COARSE = 32  # points along a segment on which its piece over a plane's grid is found
_PICK_GRID = 5  # views are scored on this many x this many points of a plane
_SIDES = (-1.0, 0.0, 1.0)  # a sample is on the plane when the rays through it and beside it all are
_XY = 2  # coordinates of an image point
_SEGMENT_COLS = 4  # a segment row: x0, y0, x1, y1 (a detector may add columns after these, e.g. a score)


@dataclass
class LineSupport:
    """Per grid pixel of one plane's orthophoto: how many views have a vertical (horizontal) segment
    through it, and how many views were read."""

    vert: np.ndarray  # (H, W) int16
    horiz: np.ndarray  # (H, W) int16
    n_views: int

    def lines(self, min_views: int) -> tuple[np.ndarray, np.ndarray]:
        """Boolean maps of the pixels on vertical and on horizontal lines that ``min_views`` views support."""
        return self.vert >= min_views, self.horiz >= min_views


def normalised_coords(x: np.ndarray, y: np.ndarray, f: Frame, width: int, height: int,
                      c: ColourCalibration) -> np.ndarray:
    """Normalised camera coords (..., 2) of pixels (x, y) in ``f``'s colour image of ``width`` x ``height``
    under calibration ``c``: the inverse of colour_sampling.pixel_coords."""
    intr = f.intrinsics if (f.intrinsics.width, f.intrinsics.height) == (width, height) else f.intrinsics.scaled(width, height)
    s = width / REFERENCE_WIDTH_PX
    return np.stack([(np.asarray(x, float) - intr.cx - c.dx * s) / (c.scale * intr.fx),
                     (np.asarray(y, float) - intr.cy - c.dy * s) / (c.scale * intr.fy)], -1)


def rays_to_plane(xn: np.ndarray, c2w: np.ndarray, n: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray]:
    """World rays through normalised coords ``xn`` (..., 2) of a camera ``c2w``: their directions (..., 3),
    scaled so that the camera depth is 1, and the depth at which each meets the plane n·x = d (NaN where
    it meets it behind the camera, closer than 0.1 m, or never)."""
    R, C = c2w[:3, :3], c2w[:3, 3]
    dirs = np.concatenate([xn, np.ones(xn.shape[:-1] + (1,))], -1) @ R.T
    along = dirs @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (d - float(C @ n)) / along
    return dirs, np.where(np.isfinite(t) & (t > _NEAR), t, np.nan)


def segments_on_plane(seg: np.ndarray, f: Frame, width: int, height: int, c: ColourCalibration,
                      n: np.ndarray, u: np.ndarray, d: float) -> np.ndarray:
    """End points of image segments (N, 4+: x0, y0, x1, y1 in px) on the plane n·x = d as in-plane
    coordinates (N, 4: u0, z0, u1, z1; u along ``u``, z up); NaN rows where an end's ray does not meet the
    plane in front of the camera."""
    ends = seg[:, :4].reshape(-1, _XY, _XY)
    xn = normalised_coords(ends[..., 0], ends[..., 1], f, width, height, c)
    dirs, t = rays_to_plane(xn, f.c2w, n, d)
    p = f.c2w[:3, 3] + dirs * t[..., None]
    return np.stack([p[..., 0, :] @ u, p[..., 0, 2], p[..., 1, :] @ u, p[..., 1, 2]], -1)


def _samples(seg: np.ndarray, plane_len: np.ndarray, depth_ratio: np.ndarray, res: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Image points along each segment, about half a grid pixel apart on the plane (denser by the ratio
    of its ends' depths: the projection is not uniform): x, y and the segment index of each."""
    k = np.clip(np.ceil(plane_len / res * _SAMPLES_PER_PX * depth_ratio), 1, _MAX_SAMPLES).astype(int) + 1
    idx = np.repeat(np.arange(len(seg)), k)
    start = np.repeat(np.cumsum(k) - k, k)
    a = (np.arange(len(idx)) - start) / np.repeat(k - 1, k)
    x = seg[idx, 0] + a * (seg[idx, 2] - seg[idx, 0])
    y = seg[idx, 1] + a * (seg[idx, 3] - seg[idx, 1])
    return x, y, idx


def _within_grid(seg: np.ndarray, flag: np.ndarray, f: Frame, width: int, height: int, c: ColourCalibration,
                 o: Orthophoto) -> tuple[np.ndarray, np.ndarray]:
    """The pieces of image segments (N, 4) whose points land on ``o``'s grid (found on ``_COARSE`` points
    along each, widened by one step), with their ``flag``; segments missing the grid are dropped. A floor
    line carried onto a wall plane lands metres away: it is not followed there."""
    a = np.linspace(0.0, 1.0, _COARSE)
    x = seg[:, [0]] + a * (seg[:, [2]] - seg[:, [0]])
    y = seg[:, [1]] + a * (seg[:, [3]] - seg[:, [1]])
    dirs, t = rays_to_plane(normalised_coords(x, y, f, width, height, c), f.c2w, o.plane.n, o.plane.d)
    p = f.c2w[:3, 3] + dirs * t[..., None]
    H, W = o.n_views.shape
    col, row = (p @ o.plane.u - o.u0) / o.res, (o.v_top - p[..., 2]) / o.res
    with np.errstate(invalid="ignore"):
        on = np.isfinite(t) & (col > -1) & (col < W + 1) & (row > -1) & (row < H + 1)
    keep = on.any(1)
    first = np.argmax(on, 1)[keep]
    last = _COARSE - 1 - np.argmax(on[:, ::-1], 1)[keep]
    a0, a1 = a[np.maximum(first - 1, 0)], a[np.minimum(last + 1, _COARSE - 1)]
    s = seg[keep]
    d = s[:, 2:4] - s[:, 0:2]
    return np.concatenate([s[:, 0:2] + a0[:, None] * d, s[:, 0:2] + a1[:, None] * d], 1), flag[keep]


def view_lines(seg: np.ndarray, f: Frame, width: int, height: int, c: ColourCalibration, o: Orthophoto,
               raster: Rasterizer, p: LineConfig, ortho: OrthoConfig) -> tuple[np.ndarray, np.ndarray]:
    """Boolean (vertical, horizontal) line maps on ``o``'s grid from one view's segments ``seg`` (N, 4+ px
    of its colour image of ``width`` x ``height``): the segments that lie within ``max_angle_deg`` of
    vertical (horizontal) on the plane, where the plane is what the view sees along them, widened across
    by ``tol``."""
    H, W = o.n_views.shape
    vert, horiz = np.zeros((H, W), np.uint8), np.zeros((H, W), np.uint8)
    if not len(seg):
        return vert.astype(bool), horiz.astype(bool)
    pl = o.plane
    ends = segments_on_plane(seg, f, width, height, c, pl.n, pl.u, pl.d)
    du, dz = ends[:, 2] - ends[:, 0], ends[:, 3] - ends[:, 1]
    tan = np.tan(np.radians(p.max_angle_deg))
    is_v = np.abs(du) <= tan * np.abs(dz)
    is_h = np.abs(dz) <= tan * np.abs(du)
    keep = np.isfinite(ends).all(1) & (is_v | is_h)
    if not keep.any():
        return vert.astype(bool), horiz.astype(bool)
    seg, is_v = _within_grid(seg[keep, :4], is_v[keep], f, width, height, c, o)
    if not len(seg):
        return vert.astype(bool), horiz.astype(bool)
    # the pieces' ends on the plane, and their depths: the sampling is denser where the projection stretches
    ends = segments_on_plane(seg, f, width, height, c, pl.n, pl.u, pl.d)
    xn_ends = normalised_coords(seg[:, [0, 2]], seg[:, [1, 3]], f, width, height, c)
    t_ends = rays_to_plane(xn_ends, f.c2w, pl.n, pl.d)[1]
    ratio = np.nanmax(t_ends, 1) / np.nanmin(t_ends, 1)
    x, y, idx = _samples(seg, np.hypot(ends[:, 2] - ends[:, 0], ends[:, 3] - ends[:, 1]), ratio, o.res)
    # the plane is what the view sees at the sample and a margin to either side of the segment
    normal = np.stack([-(seg[:, 3] - seg[:, 1]), seg[:, 2] - seg[:, 0]], 1)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-9)
    margin = ortho.erode_px / ortho.render_scale * width / REFERENCE_WIDTH_PX
    pts = np.stack([x, y], 1)[None] + np.array(_SIDES)[:, None, None] * margin * normal[idx][None]
    xn = normalised_coords(pts[..., 0], pts[..., 1], f, width, height, c)
    dirs, t_plane = rays_to_plane(xn, f.c2w, pl.n, pl.d)
    hit = raster.cast_rays(np.broadcast_to(f.c2w[:3, 3], dirs.shape), dirs).t
    with np.errstate(invalid="ignore"):
        on = np.abs(hit - t_plane) < ortho.depth_tol + ortho.depth_tol_rel * t_plane
    seen = on.all(0)
    world = f.c2w[:3, 3] + dirs[_SIDES.index(0.0)] * t_plane[_SIDES.index(0.0)][:, None]
    col = np.floor((world @ pl.u - o.u0) / o.res)
    row = np.floor((o.v_top - world[:, 2]) / o.res)
    seen &= (col >= 0) & (col < W) & (row >= 0) & (row < H)
    col, row, sv = col[seen].astype(int), row[seen].astype(int), is_v[idx[seen]]
    vert[row[sv], col[sv]] = 1
    horiz[row[~sv], col[~sv]] = 1
    tol_px = int(round(p.tol / o.res))
    if tol_px > 0:
        vert = cv2.dilate(vert, np.ones((1, 2 * tol_px + 1), np.uint8))
        horiz = cv2.dilate(horiz, np.ones((2 * tol_px + 1, 1), np.uint8))
    return vert.astype(bool), horiz.astype(bool)


def pick_line_views(orthos: Sequence[Orthophoto], frames: Sequence[Frame], p: LineConfig,
                    ortho: OrthoConfig) -> list[list[int]]:
    """Per plane, the frames whose segments are read: those seeing most of it (5 x 5 points of its grid in
    the image, in front of the camera, at least ``ortho.min_cos`` to the view ray, weighted by that cosine),
    at most ``views_per_plane``, spread apart (each next one the farthest from those chosen among the
    frames scoring at least half the best); then at most ``max_frames`` frames over all planes, those
    serving the most plane area (each plane's area weighted by the view's score over its best view's)."""
    if not frames or not orthos:
        return [[] for _ in orthos]
    centers = np.array([f.c2w[:3, 3] for f in frames])
    w2cs = np.array([f.w2c for f in frames])
    Ks = np.array([f.intrinsics.K for f in frames])
    size = np.array([(f.intrinsics.width, f.intrinsics.height) for f in frames], float)
    per_plane: list[list[int]] = []
    value = np.zeros(len(frames))
    for o in orthos:
        H, W = o.n_views.shape
        cols, rows = np.meshgrid(np.linspace(0, W - 1, _PICK_GRID), np.linspace(0, H - 1, _PICK_GRID))
        sample = o.plane.to_world(*o.to_uv(cols.ravel(), rows.ravel()))
        inside = project_into_views(sample, w2cs, Ks, size)[3]
        ray = sample[None] - centers[:, None]
        cos = -(ray @ o.plane.n) / np.maximum(np.linalg.norm(ray, axis=-1), 1e-9)
        score = (cos * (inside & (cos >= ortho.min_cos))).sum(1)
        cand = np.flatnonzero((score > 0) & (score >= 0.5 * score.max()))
        chosen: list[int] = []
        if len(cand):
            chosen.append(int(cand[np.argmax(score[cand])]))
            dist = np.linalg.norm(centers[cand] - centers[chosen[0]], axis=1)
            while len(chosen) < min(p.views_per_plane, len(cand)):
                nxt = int(np.argmax(dist))
                if dist[nxt] <= 0:
                    break
                chosen.append(int(cand[nxt]))
                dist = np.minimum(dist, np.linalg.norm(centers[cand] - centers[cand[nxt]], axis=1))
        per_plane.append(chosen)
        value[chosen] += o.plane.area * score[chosen] / score.max()
    order = np.argsort(-value, kind="stable")[:p.max_frames]
    keep = set(order[value[order] > 0].tolist())
    return [[fi for fi in ch if fi in keep] for ch in per_plane]


def line_support(orthos: Sequence[Orthophoto], frames: Sequence[Frame], raster: Rasterizer,
                 read_rgb: Callable[[Frame], np.ndarray], detect: Callable[[np.ndarray], np.ndarray],
                 calibration: Callable[[int], ColourCalibration], cfg: HeuristicConfig) -> list[LineSupport]:
    """The learned line support of every plane (see module docstring): ``detect`` runs once per frame
    chosen by :func:`pick_line_views`, on the image ``read_rgb`` gives; ``calibration(frame index)`` is the
    colour correction the orthophotos used for that view."""
    p = cfg.lines
    picks = pick_line_views(orthos, frames, p, cfg.ortho)
    out = [LineSupport(np.zeros(o.n_views.shape, np.int16), np.zeros(o.n_views.shape, np.int16), 0) for o in orthos]
    for fi in sorted({fi for ch in picks for fi in ch}):
        img = read_rgb(frames[fi])
        seg = np.asarray(detect(img), float)
        seg = seg.reshape(len(seg), -1) if seg.size else np.zeros((0, _SEGMENT_COLS))
        h, w = img.shape[:2]
        for i, ch in enumerate(picks):
            if fi in ch:
                v, hz = view_lines(seg, frames[fi], w, h, calibration(fi), orthos[i], raster, p, cfg.ortho)
                out[i].vert += v
                out[i].horiz += hz
                out[i].n_views += 1
    return out

