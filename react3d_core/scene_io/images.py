"""Reading the pixels behind an :class:`ImageRef`: RGB (file or video frame) and depth (metres)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np

from ..data.frames import Frame, ImageRef
from ..errors import InputError
from .depth_bin import DepthBin


@lru_cache(maxsize=8)
def _depth_bin(path: str) -> DepthBin:
    return DepthBin(path)


class _Video:
    """Sequential-friendly reader of a video container (seeks only when asked out of order)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.cap = cv2.VideoCapture(str(path))
        if not self.cap.isOpened():
            raise InputError(path, "cannot open video")
        self.next_index = 0

    def read(self, index: int) -> np.ndarray:
        if index != self.next_index:
            self.cap.set(cv2.CAP_PROP_POS_FRAMES, index)
        ok, img = self.cap.read()
        if not ok:
            raise InputError(self.path, f"cannot decode video frame {index}")
        self.next_index = index + 1
        return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


@lru_cache(maxsize=4)
def _video(path: str) -> _Video:
    return _Video(Path(path))


def read_rgb(ref: ImageRef) -> np.ndarray:
    """RGB uint8 (H, W, 3)."""
    if ref.kind == "mkv":
        return _video(str(ref.path)).read(int(ref.index or 0))
    if not ref.path.is_file():
        raise InputError(ref.path, "image file not found")
    img = cv2.imread(str(ref.path), cv2.IMREAD_COLOR)
    if img is None:
        raise InputError(ref.path, "cannot decode image")
    return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


def read_depth(ref: ImageRef, depth_scale: float = 0.001) -> np.ndarray:
    """Depth in metres, float32 (H, W), 0 where invalid."""
    if ref.kind in ("depth_bin_lz4", "depth_bin_deflate", "depth_bin_deflate_stream"):
        return _depth_bin(str(ref.path)).read(int(ref.index or 0))
    if not ref.path.is_file():
        raise InputError(ref.path, "depth file not found")
    if ref.kind == "npy":
        d = np.load(ref.path, allow_pickle=False).astype(np.float32)
    else:
        d = cv2.imread(str(ref.path), cv2.IMREAD_UNCHANGED)
        if d is None:
            raise InputError(ref.path, "cannot decode depth image")
        d = d.astype(np.float32) * depth_scale
    d[~np.isfinite(d)] = 0
    return d


def read_label_image(ref: ImageRef) -> np.ndarray:
    """An integer label image (e.g. ground-truth part ids, 16-bit PNG or .npy), int32."""
    if not ref.path.is_file():
        raise InputError(ref.path, "label image not found")
    if ref.kind == "npy":
        return np.load(ref.path, allow_pickle=False).astype(np.int32)
    img = cv2.imread(str(ref.path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise InputError(ref.path, "cannot decode label image")
    return img.astype(np.int32)


def frame_rgb(frame: Frame) -> np.ndarray:
    return read_rgb(frame.rgb)


def frame_depth(frame: Frame) -> np.ndarray | None:
    return None if frame.depth is None else read_depth(frame.depth, frame.depth_scale)
