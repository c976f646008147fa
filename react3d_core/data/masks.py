"""2D masks and per-view articulation predictions; arrays stored as bit-packed compressed npz."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ..atomic import read_npz, write_npz
from ..errors import InputError


class Mask2D(BaseModel):
    """A binary mask on one frame (at the frame's RGB resolution), with its label and score."""

    model_config = ConfigDict(arbitrary_types_allowed=True)

    frame_id: str
    label: str = "openable"
    score: float = 1.0
    mask: np.ndarray = Field(repr=False, description="bool HxW")
    box: tuple[float, float, float, float] | None = Field(None, description="x0, y0, x1, y1 (px)")
    instance: int | None = Field(None, description="The perceived object this mask shows, the same in every frame, when the backend knows it (a 3D front rendered into each view); None for per-view detectors.")

    @property
    def area(self) -> int:
        return int(self.mask.sum())


class ArticulationPrediction(BaseModel):
    """One articulated-part prediction on one view, in that view's camera frame (OpenCV axes).

    This is what OPDMulti gives: a part mask, a joint type, an axis and an origin. The origin may
    come as a 3D camera-frame point or only as a pixel (then depth lifts it, see the articulation stage).
    """

    model_config = ConfigDict(arbitrary_types_allowed=True)

    frame_id: str
    mask: np.ndarray = Field(repr=False, description="bool HxW at the frame's RGB resolution")
    joint_type: Literal["revolute", "prismatic"]
    axis_cam: tuple[float, float, float]
    origin_cam: tuple[float, float, float] | None = None
    origin_px: tuple[float, float] | None = None
    score: float = 1.0
    sliding: bool = Field(False, description="Prismatic motion in the front's plane (a sliding door), not out of it.")


def save_masks(path: str | Path, masks: Sequence[Mask2D]) -> Path:
    """Write masks to one compressed npz (bit-packed), metadata as arrays (no pickles)."""
    if masks:
        h, w = masks[0].mask.shape
        if any(m.mask.shape != (h, w) for m in masks):
            raise ValueError("all masks in one file must share a shape")
        bits = np.stack([np.packbits(m.mask.astype(bool).ravel()) for m in masks])
    else:
        h = w = 0
        bits = np.zeros((0, 0), np.uint8)
    boxes = np.array([m.box if m.box is not None else (np.nan,) * 4 for m in masks], dtype=float).reshape(-1, 4)
    return write_npz(
        path,
        bits=bits,
        shape=np.array([h, w]),
        frame_id=np.array([m.frame_id for m in masks], dtype=str),
        label=np.array([m.label for m in masks], dtype=str),
        score=np.array([m.score for m in masks], dtype=float),
        box=boxes,
        instance=np.array([-1 if m.instance is None else m.instance for m in masks], dtype=np.int64),
    )


def load_masks(path: str | Path) -> list[Mask2D]:
    """Read masks written by :func:`save_masks`."""
    z = read_npz(path)
    try:
        h, w = (int(x) for x in z["shape"])
        inst = z["instance"] if "instance" in z else np.full(len(z["frame_id"]), -1)  # archives written before it
        out = []
        for i in range(len(z["frame_id"])):
            m = np.unpackbits(z["bits"][i], count=h * w).astype(bool).reshape(h, w)
            box = z["box"][i]
            out.append(
                Mask2D(
                    frame_id=str(z["frame_id"][i]),
                    label=str(z["label"][i]),
                    score=float(z["score"][i]),
                    mask=m,
                    box=None if np.isnan(box).any() else tuple(float(b) for b in box),
                    instance=None if int(inst[i]) < 0 else int(inst[i]),
                )
            )
        return out
    except KeyError as exc:
        raise InputError(path, f"mask archive lacks field {exc}") from None


_Packed = tuple[bytes, tuple[int, int], str, str, float, "tuple | None", "int | None"]


class _PackedFrame(Sequence[Mask2D]):
    """One frame's packed masks; each is unpacked only when indexed (top-k views read one or two)."""

    def __init__(self, packed: list[_Packed]) -> None:
        self._packed = packed

    def __len__(self) -> int:
        return len(self._packed)

    def __getitem__(self, i):  # noqa: ANN001, ANN204 - Sequence protocol (int or slice)
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        bits, (h, w), fid, label, score, box, instance = self._packed[i]
        mask = np.unpackbits(np.frombuffer(bits, np.uint8), count=h * w).astype(bool).reshape(h, w)
        return Mask2D(frame_id=fid, label=label, score=score, mask=mask, box=box, instance=instance)


class PackedMasks(Mapping[str, Sequence[Mask2D]]):
    """Frame id -> masks, held bit-packed (1 bit per pixel) and unpacked on access.

    Fusion reads every frame's masks once to lift them and a few again for the top-k views, so a
    scene's masks need not sit unpacked in memory: a 960x720 mask is 691 kB as bools, 86 kB packed.
    """

    def __init__(self) -> None:
        self._frames: dict[str, list[_Packed]] = {}

    def add(self, frame_id: str, masks: Sequence[Mask2D]) -> None:
        """Store (replace) one frame's masks, packed."""
        self._frames[frame_id] = [
            (np.packbits(m.mask.astype(bool).ravel()).tobytes(), tuple(m.mask.shape), m.frame_id, m.label,
             float(m.score), m.box, m.instance) for m in masks]

    def __getitem__(self, frame_id: str) -> Sequence[Mask2D]:
        return _PackedFrame(self._frames[frame_id])

    def __iter__(self) -> Iterator[str]:
        return iter(self._frames)

    def __len__(self) -> int:
        return len(self._frames)

    @property
    def nbytes(self) -> int:
        """Bytes held by the packed masks."""
        return sum(len(m[0]) for ms in self._frames.values() for m in ms)

