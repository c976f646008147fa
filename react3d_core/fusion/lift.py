"""Per-frame lifting: which visible mesh faces lie under each (hole-filled, eroded) 2D mask.

A mask's pixels that see through the front (a glass pane the scan lacks, or a hole filled over the
cabinet's inside) are not lifted: the part is what lies on the plane of the mask's outline.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy import ndimage

from ..camera import scaled_area_px, scaled_px
from ..config import PipelineConfig
from ..data.masks import Mask2D
from ..raster.rasterizer import RasterResult

def fill_holes(mask: np.ndarray, close_px: int) -> np.ndarray:
    """Close gaps up to ``close_px`` (at 960 px width) then fill enclosed holes.

    Why: detectors miss handles and knobs, leaving holes or notches in door masks; the faces
    behind them must still be lifted with the door. Works on the mask's bounding box only.
    """
    m = np.asarray(mask, bool)
    ys = np.flatnonzero(m.any(1))
    if not len(ys):
        return m.copy()
    xs = np.flatnonzero(m.any(0))
    y0, y1, x0, x1 = ys[0], ys[-1] + 1, xs[0], xs[-1] + 1
    crop = m[y0:y1, x0:x1]
    k = scaled_px(close_px, m.shape[1])
    if k >= 2:
        mp = np.pad(crop.astype(np.uint8), k)
        kern = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k | 1, k | 1))
        crop = cv2.morphologyEx(mp, cv2.MORPH_CLOSE, kern)[k:-k, k:-k].astype(bool)
    out = np.zeros_like(m)
    out[y0:y1, x0:x1] = ndimage.binary_fill_holes(crop)
    return out


def resize_mask(mask: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Nearest-neighbour resize of a bool mask to ``shape`` (H, W)."""
    if mask.shape == shape:
        return mask.astype(bool)
    return cv2.resize(mask.astype(np.uint8), (shape[1], shape[0]), interpolation=cv2.INTER_NEAREST).astype(bool)


def erode(mask: np.ndarray, px: int) -> np.ndarray:
    if px <= 0 or not mask.any():
        return mask
    return cv2.erode(mask.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * px + 1, 2 * px + 1))).astype(bool)


@dataclass
class FrameLift:
    """One frame's lifted masks: ``face_sets[i]`` are the visible faces under mask ``mask_index[i]``."""

    frame_id: str
    face_sets: list[np.ndarray] = field(default_factory=list)
    mask_index: list[int] = field(default_factory=list)


def through_pixels(mask: np.ndarray, depth: np.ndarray, band_px: int, behind_m: float, min_band: int = 12,
                   image_sides: tuple[bool, bool, bool, bool] = (True, True, True, True), min_inliers: float = 0.7,
                   min_spread: float = 1.0) -> np.ndarray:
    """Pixels of ``mask`` whose surface (``depth``, metres, 0 = none) lies more than ``behind_m`` behind
    the plane of the mask's outline: the ``band_px`` wide band inside the mask's edge. Where the mask
    runs into the image's border it is cut off, not outlined: ``image_sides`` (top, bottom, left,
    right) say which sides of the arrays are the image's border (all of them for a whole image).

    Why: a frame around a glass pane is one part, but the scan mostly lacks the pane, so inside the
    frame the views show the shelves and back wall behind it; a hole filled over a missed handle can
    likewise reach what lies behind. The outline of a front lies on the front (frame, edges), so its
    plane tells what is seen through. A plane is affine in inverse depth over pixel coordinates
    (1/z = a u + b v + c for any pinhole camera), fitted by least squares and trimmed twice; no
    intrinsics needed. Pixels in front of the plane (handles) are never through.

    The outline must tell a plane: at least ``min_band`` band pixels with depth, ``min_inliers`` of them
    within ``behind_m`` of the fit, spread over ``min_spread`` x ``band_px`` (standard deviation) both
    ways (a mask cut off by the image on three sides has one edge of outline, a line, through which
    any plane fits), and the fit in front of the camera. A through region is a panel, not a sliver:
    only connected regions holding a pixel ``band_px`` from their edge count (a front seen at a grazing
    angle, or one whose faces reach a few cm deep, has thin strips off any plane).
    """
    m = np.asarray(mask, bool)
    out = np.zeros(m.shape, bool)
    ys = np.flatnonzero(m.any(1))
    if not len(ys) or band_px <= 0:
        return out
    xs = np.flatnonzero(m.any(0))
    y0, y1, x0, x1 = ys[0], ys[-1] + 1, xs[0], xs[-1] + 1
    mc = m[y0:y1, x0:x1]
    z = np.asarray(depth, np.float32)[y0:y1, x0:x1]
    has = mc & (z > 0)
    top, bottom, left, right = image_sides
    cut = (top and y0 == 0, bottom and y1 == m.shape[0], left and x0 == 0, right and x1 == m.shape[1])
    padded = np.pad(mc, 1)  # past the crop's edge the mask ends, unless that edge is the image's border
    padded[0, :], padded[-1, :] = (padded[1, :] if cut[0] else False), (padded[-2, :] if cut[1] else False)
    padded[:, 0], padded[:, -1] = (padded[:, 1] if cut[2] else False), (padded[:, -2] if cut[3] else False)
    band = has & ~erode(padded, band_px)[1:-1, 1:-1]
    inner = has & ~band
    if band.sum() < min_band or not inner.any():
        return out
    by, bx = np.nonzero(band)
    A = np.stack([bx, by, np.ones_like(bx)], 1).astype(np.float64)
    zb = z[by, bx].astype(np.float64)
    keep = np.ones(len(zb), bool)
    coef = None
    for tol in (np.inf, 2.0 * behind_m, behind_m):
        if keep.sum() < min_band:
            break
        coef = np.linalg.lstsq(A[keep], 1.0 / zb[keep], rcond=None)[0]
        wfit = A @ coef
        zfit = np.divide(1.0, wfit, out=np.full_like(wfit, np.inf), where=wfit > 0)
        keep = np.abs(zb - zfit) < tol
    if coef is None or keep.mean() < min_inliers:
        return out
    spread = np.linalg.eigvalsh(np.cov(np.stack([bx[keep], by[keep]]).astype(np.float64)))
    if np.sqrt(max(float(spread[0]), 0.0)) < min_spread * band_px:
        return out
    iy, ix = np.nonzero(inner)
    w = coef[0] * ix + coef[1] * iy + coef[2]
    if not (w > 0).all():
        return out
    zi = z[iy, ix].astype(np.float64)
    thr = np.nonzero(zi > 1.0 / w + behind_m)[0]
    th = np.zeros(mc.shape, np.uint8)
    th[iy[thr], ix[thr]] = 1
    n, lab = cv2.connectedComponents(th, connectivity=8)
    core = np.unique(lab[erode(th.astype(bool), band_px)])
    out[y0:y1, x0:x1] = np.isin(lab, core[core > 0])
    return out


def filled(mask: np.ndarray, shape: tuple[int, int], config: PipelineConfig, depth: np.ndarray | None = None) -> np.ndarray:
    """Mask resized to ``shape`` (nearest) with its holes filled (missed handles); with the raster's
    ``depth`` (at ``shape``), without the pixels that see through the front (:func:`through_pixels`)."""
    m = fill_holes(resize_mask(mask, shape), config.perception.hole_close_px)
    return m if depth is None else not_through(m, depth, config, shape[1])


def not_through(mask: np.ndarray, depth: np.ndarray, config: PipelineConfig, width: int,
                image_sides: tuple[bool, bool, bool, bool] = (True, True, True, True)) -> np.ndarray:
    """``mask`` without its pixels that see through the front; ``width``: the image's width (``mask``
    and ``depth`` may be a crop of it, whose ``image_sides`` (top, bottom, left, right) are the image's
    border), which scales ``fusion.through_band_px``."""
    band = scaled_px(config.fusion.through_band_px, width)
    if config.fusion.through_band_px <= 0:
        return mask
    return mask & ~through_pixels(mask, depth, max(1, band), config.clip.keep_behind_m, image_sides=image_sides)


def prepare_mask(mask: np.ndarray, shape: tuple[int, int], config: PipelineConfig, depth: np.ndarray | None = None) -> np.ndarray:
    """Mask at the raster's size, holes filled (handles), without what is seen through the front
    (``depth`` given), eroded (boundary bleed)."""
    return erode(filled(mask, shape, config, depth), scaled_px(config.fusion.erode_px, shape[1]))


def lift_masks(raster: RasterResult, masks: Sequence[Mask2D], config: PipelineConfig) -> FrameLift:
    """Visible faces under each eroded mask through the raster's face-id buffer (empty sets dropped)."""
    ids = raster.face_ids
    out = FrameLift(raster.frame_id)
    for i, mk in enumerate(masks):
        m = prepare_mask(mk.mask, ids.shape, config, raster.depth)
        f = ids[m]
        f = np.unique(f[f >= 0])
        if len(f):
            out.face_sets.append(f.astype(np.int64))
            out.mask_index.append(i)
    return out


@dataclass
class ViewStats:
    """What top-k needs of one frame, without its pixels: the face histogram of the whole buffer and,
    per usable mask (hole-filled, not eroded), the faces under it with pixel counts and its area."""

    frame_id: str
    faces: np.ndarray
    counts: np.ndarray
    mask_index: list[int] = field(default_factory=list)
    mask_faces: list[np.ndarray] = field(default_factory=list)
    mask_counts: list[np.ndarray] = field(default_factory=list)
    mask_area: list[int] = field(default_factory=list)
    at_border: list[bool] = field(default_factory=list)


def _histogram(ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    f, c = np.unique(ids, return_counts=True)
    keep = f >= 0
    return f[keep].astype(np.int64), c[keep].astype(np.int64)


def lift_with_stats(raster: RasterResult, masks: Sequence[Mask2D], config: PipelineConfig) -> tuple[FrameLift, ViewStats]:
    """``lift_masks`` plus the frame's :class:`ViewStats`, sharing the hole filling."""
    ids = raster.face_ids
    shape = ids.shape
    w = shape[1]
    lift = FrameLift(raster.frame_id)
    f_all, c_all = _histogram(ids)
    stats = ViewStats(raster.frame_id, f_all, c_all)
    b = scaled_px(config.topk.border_px, masks[0].mask.shape[1]) if masks else 0
    e = scaled_px(config.fusion.erode_px, w)
    for i, mk in enumerate(masks):
        full = mk.mask
        if not full.any():
            continue
        filled_m = filled(full, shape, config, raster.depth)
        f = ids[erode(filled_m, e)]
        f = np.unique(f[f >= 0])
        if len(f):
            lift.face_sets.append(f.astype(np.int64))
            lift.mask_index.append(i)
        area = int(full.sum())
        if area < scaled_area_px(config.topk.min_mask_px, full.shape[1]):
            continue
        mf, mc = _histogram(ids[filled_m])
        stats.mask_index.append(i)
        stats.mask_faces.append(mf)
        stats.mask_counts.append(mc)
        stats.mask_area.append(int(filled_m.sum()))
        stats.at_border.append(b > 0 and bool(full[:b].any() or full[-b:].any() or full[:, :b].any() or full[:, -b:].any()))
    return lift, stats
