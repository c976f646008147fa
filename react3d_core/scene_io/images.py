"""Reading the pixels behind an :class:`ImageRef`: RGB (file or video frame), depth (metres), and image sizes
from file headers."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from PIL import Image as PILImage

from ..data.frames import Frame, ImageRef
from ..errors import InputError
from ..npyio import load_npy
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


def check_jpeg_complete(path: Path) -> None:
    """Raise when a JPEG lacks its end-of-image marker: libjpeg only warns on a truncated file and
    returns an image whose missing rows are grey, which the stages would take for real pixels."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(2)
            fh.seek(0, 2)
            size = fh.tell()
            fh.seek(max(0, size - 4096))
            tail = fh.read()
    except OSError as exc:
        raise InputError(path, f"cannot read image ({exc.strerror})") from None
    if head != b"\xff\xd8":
        raise InputError(path, "not a JPEG file (no start-of-image marker)")
    if b"\xff\xd9" not in tail.rstrip(b"\x00"):  # EOI; cameras may pad or append a little after it
        raise InputError(path, f"truncated JPEG ({size} bytes, no end-of-image marker): re-extract or re-copy this frame")


def image_size(path: Path) -> tuple[int, int]:
    """(width, height) of an image file or of the first frame of a video. PNG and JPEG sizes come from
    their headers (a scan's check ran 250 full decodes of depth PNGs before Prefect even started)."""
    suffix = path.suffix.lower()
    if suffix == ".png" and (size := png_size(path)) is not None:
        return size
    if suffix in (".jpg", ".jpeg"):
        check_jpeg_complete(path)
        try:
            with PILImage.open(path) as im:
                return int(im.size[0]), int(im.size[1])
        except (OSError, SyntaxError):
            raise InputError(path, "cannot decode image") from None
    if path.suffix.lower() in (".mkv", ".mp4"):
        cap = cv2.VideoCapture(str(path))
        ok, img = cap.read()
        cap.release()
    else:
        img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        ok = img is not None
    if not ok:
        raise InputError(path, "cannot decode image")
    return int(img.shape[1]), int(img.shape[0])


def png_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from a PNG's IHDR chunk (24 bytes read), None when it is not a PNG."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def read_rgb(ref: ImageRef) -> np.ndarray:
    """RGB uint8 (H, W, 3)."""
    if ref.kind == "mkv":
        return _video(str(ref.path)).read(int(ref.index or 0))
    if not ref.path.is_file():
        raise InputError(ref.path, "image file not found")
    if ref.path.suffix.lower() in (".jpg", ".jpeg"):
        check_jpeg_complete(ref.path)
    img = cv2.imread(str(ref.path), cv2.IMREAD_COLOR)
    if img is None:
        raise InputError(ref.path, "cannot decode image")
    return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


def _npy(path: Path) -> np.ndarray:
    """The array in an input ``.npy`` file; a bad one is an ``InputError`` naming it, not numpy's traceback."""
    try:
        return load_npy(path)
    except (OSError, ValueError) as exc:
        raise InputError(path, f"not a readable .npy array ({exc})") from None


def read_depth(ref: ImageRef, depth_scale: float = 0.001) -> np.ndarray:
    """Depth in metres, float32 (H, W), 0 where invalid."""
    if ref.kind in ("depth_bin_lz4", "depth_bin_deflate", "depth_bin_deflate_stream"):
        return _depth_bin(str(ref.path)).read(int(ref.index or 0))
    if not ref.path.is_file():
        raise InputError(ref.path, "depth file not found")
    if ref.kind == "npy":
        d = _npy(ref.path).astype(np.float32)
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
        return _npy(ref.path).astype(np.int32)
    img = cv2.imread(str(ref.path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise InputError(ref.path, "cannot decode label image")
    return img.astype(np.int32)


def frame_rgb(frame: Frame) -> np.ndarray:
    return read_rgb(frame.rgb)


def frame_depth(frame: Frame) -> np.ndarray | None:
    """The frame's depth in metres, checked against the size its intrinsics declare: a depth map of
    another size would be read with the wrong K and give wrong cavity depths and limits."""
    if frame.depth is None:
        return None
    d = read_depth(frame.depth, frame.depth_scale)
    k = frame.depth_intrinsics
    if k is not None and d.shape[:2] != (k.height, k.width):
        raise InputError(frame.depth.path, depth_size_problem(frame.frame_id, d.shape[1], d.shape[0], k.width, k.height))
    return d


def depth_size_problem(frame_id: str, w: int, h: int, dw: int, dh: int) -> str:
    """One line for a depth map whose size differs from the declared one."""
    return (f"{frame_id}: depth image is {w}x{h} but the scan declares {dw}x{dh}; "
            "re-export the depth at the declared size (react3d does not guess how it was resized)")
