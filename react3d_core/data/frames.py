"""Frames and scene input: where the pixels are, the camera intrinsics and the camera-to-world pose.

Conventions (DESIGN.md): world = scan frame, metres, z up; poses are 4x4 camera-to-world with
OpenCV camera axes (x right, y down, z forward). Intrinsics belong to the image they describe.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

ImageKind = Literal["png", "jpg", "exr", "npy", "mkv", "depth_bin_lz4", "depth_bin_deflate", "depth_bin_deflate_stream"]


class ImageRef(BaseModel):
    """Where one image lives: a file, or frame ``index`` inside a container (``rgb.mkv``, ``depth.bin``)."""

    model_config = ConfigDict(frozen=True)

    path: Path
    kind: ImageKind
    index: int | None = Field(None, description="Frame index inside a container file.")


class Intrinsics(BaseModel):
    """Pinhole intrinsics for an image of ``width`` x ``height`` pixels."""

    model_config = ConfigDict(frozen=True)

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    @model_validator(mode="after")
    def _positive(self) -> "Intrinsics":
        vals = (self.fx, self.fy, self.cx, self.cy)
        if not all(np.isfinite(vals)):
            raise ValueError(f"intrinsics must be finite, got fx={self.fx} fy={self.fy} cx={self.cx} cy={self.cy}")
        if self.fx <= 0 or self.fy <= 0:
            raise ValueError(f"focal lengths must be positive, got fx={self.fx} fy={self.fy}")
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"image size must be positive, got {self.width}x{self.height}")
        return self

    @property
    def K(self) -> np.ndarray:
        """3x3 intrinsic matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @classmethod
    def from_K(cls, K: np.ndarray | list, width: int, height: int) -> "Intrinsics":
        K = np.asarray(K, dtype=float)
        return cls(fx=K[0, 0], fy=K[1, 1], cx=K[0, 2], cy=K[1, 2], width=int(width), height=int(height))

    def scaled(self, width: int, height: int) -> "Intrinsics":
        """Intrinsics of the same camera for the image resized to ``width`` x ``height``.

        Pixel-edge convention: a pixel centre u maps to (u + 0.5) * s - 0.5; for the ScanNet++
        toolkit's plain scaling (cx * s) set ``half_pixel=False`` upstream. We use plain scaling,
        which is what ScanNet++ (K * 256/1920) and the reference code do.
        """
        sx, sy = width / self.width, height / self.height
        return Intrinsics(fx=self.fx * sx, fy=self.fy * sy, cx=self.cx * sx, cy=self.cy * sy, width=width, height=height)


def validate_pose(pose: np.ndarray, tol: float = 1e-3) -> np.ndarray:
    """Check a 4x4 camera-to-world pose: finite, last row [0 0 0 1], rigid rotation (det +1)."""
    pose = np.asarray(pose, dtype=float)
    if pose.shape != (4, 4):
        raise ValueError(f"pose must be 4x4, got shape {pose.shape}")
    if not np.all(np.isfinite(pose)):
        raise ValueError("pose contains NaN or inf")
    if not np.allclose(pose[3], [0, 0, 0, 1], atol=1e-6):
        raise ValueError(f"pose last row must be [0 0 0 1], got {pose[3].tolist()}")
    R = pose[:3, :3]
    err = np.abs(R @ R.T - np.eye(3)).max()
    if err > tol:
        raise ValueError(f"pose rotation is not orthonormal (max |RR^T - I| = {err:.3g})")
    if np.linalg.det(R) < 0:
        raise ValueError("pose rotation is a reflection (det < 0)")
    return pose


class Frame(BaseModel):
    """One posed RGB-D frame."""

    model_config = ConfigDict(frozen=True, arbitrary_types_allowed=True)

    frame_id: str = Field(description="Stable id, e.g. 'frame_000120'.")
    rgb: ImageRef
    depth: ImageRef | None = None
    intrinsics: Intrinsics = Field(description="Intrinsics of the RGB image as stored.")
    depth_intrinsics: Intrinsics | None = Field(None, description="Intrinsics of the depth image (may differ in size).")
    pose: tuple[tuple[float, float, float, float], ...] = Field(description="4x4 camera-to-world, OpenCV axes.")
    depth_scale: float = Field(0.001, gt=0, description="Metres per stored depth unit (0.001 for uint16 mm).")
    timestamp: float | None = None
    part_ids: ImageRef | None = Field(None, description="Ground-truth part-id image (synthetic scenes only).")

    @field_validator("pose", mode="before")
    @classmethod
    def _check_pose(cls, v: object) -> tuple:
        arr = validate_pose(np.asarray(v, dtype=float))
        return tuple(tuple(float(x) for x in row) for row in arr)

    @property
    def c2w(self) -> np.ndarray:
        """4x4 camera-to-world (OpenCV axes)."""
        return np.array(self.pose, dtype=float)

    @property
    def w2c(self) -> np.ndarray:
        """4x4 world-to-camera."""
        T = self.c2w
        out = np.eye(4)
        out[:3, :3] = T[:3, :3].T
        out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
        return out


class SceneInput(BaseModel):
    """A static scan: the mesh, the frames, and where ground truth lives if any."""

    model_config = ConfigDict(frozen=True)

    scene_id: str
    root: Path
    mesh_path: Path
    frames: tuple[Frame, ...]
    source_format: str = Field(description="The input layout it was loaded from: 'scannetpp_iphone', 'prepared', 'generic', 'scannetpp_dslr' (scene_io.LAYOUTS).")
    gt_dir: Path | None = Field(None, description="Folder with Articulate3D <scan>_parts.json / _artic.json.")
    notes: tuple[str, ...] = Field((), description="Non-fatal problems found while loading.")
    frame_selection: str = Field("", description="How the frames were chosen: kept N of M and by which rule.")

    def frame(self, frame_id: str) -> Frame:
        for f in self.frames:
            if f.frame_id == frame_id:
                return f
        raise KeyError(frame_id)
