"""Read ``.npy`` and ``.npz`` files without ``ast``: safe to call from many threads at once.

Why: numpy parses each array header with ``ast.literal_eval``. On CPython 3.11 the AST
constructor keeps one recursion counter per interpreter, not per thread, so two threads building
ASTs at once can fail with ``SystemError: AST constructor recursion depth mismatch``
(python/cpython#106905). Our tasks read cached results and depth frames from worker threads, so
the headers are parsed here with fixed patterns instead. Pickled (object) arrays are refused.
"""

from __future__ import annotations

import io
import re
import struct
import zipfile
from pathlib import Path
from typing import BinaryIO

import numpy as np

_MAGIC = b"\x93NUMPY"
_DESCR = re.compile(r"'descr'\s*:\s*'([^']+)'")
_FORTRAN = re.compile(r"'fortran_order'\s*:\s*(True|False)")
_SHAPE = re.compile(r"'shape'\s*:\s*\(([^)]*)\)")


def _header(f: BinaryIO) -> tuple[np.dtype, tuple[int, ...], bool]:
    """Dtype, shape and Fortran order from the header at the stream's position."""
    pre = f.read(8)
    if len(pre) < 8 or pre[:6] != _MAGIC:
        raise ValueError("not a .npy array (bad magic bytes)")
    major = pre[6]
    if major == 1:
        (n,) = struct.unpack("<H", f.read(2))
    elif major in (2, 3):
        (n,) = struct.unpack("<I", f.read(4))
    else:
        raise ValueError(f"unsupported .npy format version {major}.{pre[7]}")
    text = f.read(n).decode("utf-8" if major == 3 else "latin1").strip()
    descr, fortran, shape = _DESCR.search(text), _FORTRAN.search(text), _SHAPE.search(text)
    if not (text.startswith("{") and text.endswith("}") and descr and fortran and shape):
        raise ValueError(f"unsupported .npy header {text[:120]!r} (only plain, non-structured arrays)")
    dtype = np.dtype(descr.group(1))
    if dtype.hasobject:
        raise ValueError("object arrays are refused (they would need unpickling)")
    dims = tuple(int(s) for s in shape.group(1).replace(" ", "").split(",") if s)
    return dtype, dims, fortran.group(1) == "True"


def read_npy_stream(f: BinaryIO) -> np.ndarray:
    """One array from a binary stream positioned at a ``.npy`` header (a writable array)."""
    dtype, shape, fortran = _header(f)
    count = int(np.prod(shape, dtype=np.int64))
    buf = bytearray(count * dtype.itemsize)
    got = f.readinto(buf) if buf else 0
    if got != len(buf):
        raise ValueError(f"truncated .npy data: {got} of {len(buf)} bytes")
    arr = np.frombuffer(buf, dtype=dtype, count=count)
    return arr.reshape(shape, order="F" if fortran else "C")


def load_npy(path: str | Path) -> np.ndarray:
    """The array in a ``.npy`` file."""
    with open(path, "rb") as f:
        return read_npy_stream(f)


def load_npz(src: str | Path | bytes) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` archive (a path or its bytes), by name."""
    with zipfile.ZipFile(io.BytesIO(src) if isinstance(src, (bytes, bytearray)) else src) as z:
        out: dict[str, np.ndarray] = {}
        for name in z.namelist():
            with z.open(name) as f:
                out[name.removesuffix(".npy")] = read_npy_stream(f)
        return out
