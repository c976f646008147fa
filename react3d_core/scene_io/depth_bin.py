"""ScanNet++ iPhone ``depth.bin`` in both encodings (formats-facts.md).

(a) stream: the whole file is one raw-deflate stream of float32 metres, shape (N, 192, 256);
(b) per-frame: a 4-byte little-endian size + an LZ4 block of uint16 mm (192x256), with
    raw-deflate float32 metres as a per-frame fallback.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import InputError

DEPTH_H, DEPTH_W = 192, 256


def _inflate_raw(data: bytes) -> bytes:
    return zlib.decompress(data, wbits=-zlib.MAX_WBITS)


def _deflate_raw(data: bytes) -> bytes:
    c = zlib.compressobj(6, zlib.DEFLATED, -zlib.MAX_WBITS)
    return c.compress(data) + c.flush()


class DepthBin:
    """Random access to the frames of a ``depth.bin``; detects the encoding once, indexes offsets once."""

    def __init__(self, path: str | Path, height: int = DEPTH_H, width: int = DEPTH_W) -> None:
        self.path = Path(path)
        self.h, self.w = height, width
        if not self.path.is_file():
            raise InputError(self.path, "depth.bin not found")
        self._data = self.path.read_bytes()
        self._stream: np.ndarray | None = None
        self._offsets: list[tuple[int, int]] = []
        self.encoding = self._detect()

    def _detect(self) -> str:
        data, n = self._data, self.h * self.w
        # Per-frame form: walking the size headers must land exactly on the end of the file.
        pos, offs = 0, []
        while pos + 4 <= len(data):
            (size,) = struct.unpack_from("<I", data, pos)
            if size == 0 or pos + 4 + size > len(data):
                offs = []
                break
            offs.append((pos + 4, size))
            pos += 4 + size
        if offs and pos == len(data):
            self._offsets = offs
            return "per_frame"
        try:
            raw = _inflate_raw(data)
        except zlib.error:
            raise InputError(self.path, "depth.bin is neither per-frame LZ4 blocks nor a raw-deflate stream") from None
        if len(raw) % (4 * n):
            raise InputError(self.path, f"depth.bin stream holds {len(raw)} bytes, not a multiple of a {self.w}x{self.h} float32 frame")
        self._stream = np.frombuffer(raw, dtype=np.float32).reshape(-1, self.h, self.w)
        return "stream"

    def __len__(self) -> int:
        return len(self._stream) if self._stream is not None else len(self._offsets)

    def read(self, index: int) -> np.ndarray:
        """Depth of frame ``index`` in metres (float32, 0 = invalid)."""
        if not 0 <= index < len(self):
            raise InputError(self.path, f"frame index {index} out of range (file has {len(self)} frames)")
        if self._stream is not None:
            return np.array(self._stream[index])
        import lz4.block

        start, size = self._offsets[index]
        blob = self._data[start : start + size]
        n = self.h * self.w
        try:
            raw = lz4.block.decompress(blob, uncompressed_size=n * 2)
            return (np.frombuffer(raw, dtype="<u2").reshape(self.h, self.w).astype(np.float32)) / 1000.0
        except Exception:  # noqa: BLE001 - documented fallback: raw-deflate float32 metres
            try:
                raw = _inflate_raw(blob)
                return np.frombuffer(raw, dtype=np.float32).reshape(self.h, self.w).copy()
            except Exception:  # noqa: BLE001
                raise InputError(self.path, f"frame {index}: corrupt depth block") from None


def write_depth_bin(path: str | Path, depths_m: list[np.ndarray] | np.ndarray, encoding: str = "per_frame") -> Path:
    """Write depth frames (metres, 0 = invalid) as ``depth.bin`` (``per_frame`` LZ4 mm or ``stream``)."""
    path = Path(path)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        if encoding == "stream":
            arr = np.stack([np.asarray(d, np.float32) for d in depths_m])
            fh.write(_deflate_raw(arr.tobytes()))
        elif encoding == "per_frame":
            import lz4.block

            for d in depths_m:
                mm = np.clip(np.round(np.asarray(d, float) * 1000.0), 0, 65535).astype("<u2")
                blob = lz4.block.compress(mm.tobytes(), store_size=False)
                fh.write(struct.pack("<I", len(blob)))
                fh.write(blob)
        else:
            raise ValueError(f"unknown depth.bin encoding {encoding!r}")
    return path
