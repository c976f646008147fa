"""Where a scan point lands in a colour image whose intrinsics are corrected (unregistered RGB-D), and
sampling helpers shared by the orthophotos, the colour calibration and the per-view registration."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ...data.frames import Frame
from .constants import REFERENCE_WIDTH_PX

_VHW = 3  # a (views, rows, columns) stack has one channel; (views, rows, columns, channels) several
_REMAP_ROW = 1024  # points are remapped in rows of this many: cv2.remap's maps must stay under 32767 a side


@dataclass(frozen=True)
class ColourCalibration:
    """Correction of the colour intrinsics: fx, fy scaled by ``scale``; cx, cy shifted by (dx, dy)
    pixels at 640 px width; disagreement between views before and after."""

    scale: float = 1.0
    dx: float = 0.0
    dy: float = 0.0
    before: float = 0.0
    after: float = 0.0


def pixel_coords(xn: np.ndarray, f: Frame, W: int, H: int, c: ColourCalibration) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coords in ``f``'s colour image of size W x H of normalised coords ``xn`` (..., 2), under
    calibration ``c`` (its shift is in px at 640 px width)."""
    intr = f.intrinsics if (f.intrinsics.width, f.intrinsics.height) == (W, H) else f.intrinsics.scaled(W, H)
    s = W / REFERENCE_WIDTH_PX
    x = (c.scale * intr.fx * xn[..., 0] + intr.cx + c.dx * s).astype(np.float32)
    y = (c.scale * intr.fy * xn[..., 1] + intr.cy + c.dy * s).astype(np.float32)
    return x, y


@dataclass
class Points:
    """One view's seen points of a plane's (sub-sampled) grid, flattened: grid index and normalised image coords."""

    frame: int
    idx: np.ndarray  # (N,) flat index into the grid
    xn: np.ndarray   # (N, 2) float32
    edge_px: np.ndarray | None = None  # (N,) distance in the image to the nearest depth jump (px); None: far


def remap_points(img: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``img`` at (x, y) with cv2.remap's own arithmetic (maps laid out in rows of
    1024: remap's maps must stay under 32767 a side)."""
    n = len(x)
    if n == 0:
        return np.zeros(0, img.dtype)
    m = -(-n // _REMAP_ROW) * _REMAP_ROW
    mx, my = np.full(m, -1, np.float32), np.full(m, -1, np.float32)
    mx[:n], my[:n] = x, y
    out = cv2.remap(img, mx.reshape(-1, _REMAP_ROW), my.reshape(-1, _REMAP_ROW), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return out.reshape(-1)[:n]


def nanmedian(stack: np.ndarray) -> np.ndarray:
    """Per-pixel median over views (axis 0 of a (V, H, W) or (V, H, W, C) stack) ignoring NaN, 0 where
    no view. Sort-based, one channel at a time (numpy's nanmedian is ~10x slower and copies the stack)."""
    out = np.zeros(stack.shape[1:], np.float32)
    chans = [None] if stack.ndim == _VHW else range(stack.shape[-1])
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
