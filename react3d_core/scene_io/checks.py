"""Checks every layout runs on its input files at load: each problem is one InputError naming the file.

Cheap on purpose (headers, not full decodes): a scan is checked before any stage runs, and a scan of a
few hundred frames must not be decoded twice.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..data.frames import Intrinsics, validate_pose
from ..errors import InputError
from .images import depth_size_problem, png_size

DEPTH_SIZE = (256, 192)
"""ScanNet++ iPhone depth resolution (width, height); its K is the RGB K scaled by 256 / 1920."""


def read_json(path: Path) -> dict:
    if not path.is_file():
        raise InputError(path, "file not found")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise InputError(path, f"invalid JSON ({e.msg if hasattr(e, 'msg') else e})") from None


def first_message(e: Exception) -> str:
    """First message of a pydantic ValidationError (one line), else str(e)."""
    errs = getattr(e, "errors", None)
    if callable(errs):
        try:
            return str(errs()[0]["msg"]).removeprefix("Value error, ")
        except (IndexError, KeyError, TypeError):
            pass
    return str(e).splitlines()[0] if str(e) else type(e).__name__


def checked_pose(path: Path, key: str, pose: object) -> np.ndarray:
    """A 4x4 rigid camera-to-world pose, or an InputError naming the file and the frame."""
    try:
        return validate_pose(np.asarray(pose, dtype=float))
    except (ValueError, TypeError) as e:
        raise InputError(path, f"{key}: {e}") from None


def checked_intrinsics(path: Path, key: str, K: object, width: int, height: int) -> Intrinsics:
    try:
        return Intrinsics.from_K(np.asarray(K, dtype=float).reshape(3, 3), width, height)
    except (ValueError, TypeError) as e:
        raise InputError(path, f"{key}: intrinsics invalid: {first_message(e)}") from None


def check_depth_png(path: Path, frame_id: str, size: tuple[int, int]) -> None:
    """Per frame, at load: a depth PNG must have the size the layout declares (256x192 for ScanNet++)."""
    got = png_size(path)
    if got is None:
        raise InputError(path, f"{frame_id}: not a PNG depth image")
    if got != size:
        raise InputError(path, depth_size_problem(frame_id, *got, *size))


def checked_mesh(path: Path) -> Path:
    """``path`` if it is a non-empty mesh file (PLY: header checked), else an InputError."""
    if not path.is_file():
        raise InputError(path, "mesh file not found")
    if path.stat().st_size == 0:
        raise InputError(path, "mesh file is empty")
    if path.suffix.lower() == ".ply":
        check_ply_header(path)
    return path


def check_ply_header(path: Path) -> None:
    """Cheap corrupt/empty check from the PLY header alone (the full mesh is loaded only by the stages)."""
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if not head.startswith(b"ply"):
        raise InputError(path, "corrupt mesh: not a PLY file (missing 'ply' magic)")
    if b"end_header" not in head:
        raise InputError(path, "corrupt mesh: PLY header not terminated")
    counts = {}
    for line in head.split(b"end_header")[0].decode("ascii", "replace").splitlines():
        t = line.split()
        if len(t) == 3 and t[0] == "element" and t[2].isdigit():
            counts[t[1]] = int(t[2])
    if counts.get("vertex", 0) == 0 or counts.get("face", 0) == 0:
        raise InputError(path, f"empty mesh: {counts.get('vertex', 0)} vertices, {counts.get('face', 0)} faces")


def find_gt_dir(root: Path) -> Path | None:
    """The Articulate3D ground-truth folder of a ScanNet++ scene: ``articulate3d/`` in it or beside it."""
    return next((d for d in (root / "articulate3d", root.parent / "articulate3d") if d.is_dir()), None)
