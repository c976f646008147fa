"""Parts, articulations and the interactive-scene manifest.

Joint convention: a part at joint value q = 0 is in its scanned (closed) state; ``lower <= 0 <= upper``.
Revolute: x' = R(axis, q)(x - origin) + origin, q in radians. Prismatic: x' = x + q * axis, q in metres.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..atomic import read_npz, write_json, write_npz
from ..errors import InputError
from .masks import Mask2D

Vec3 = tuple[float, float, float]
JointType = Literal["revolute", "prismatic"]


def _unit(v: Any) -> Vec3:
    a = np.asarray(v, dtype=float).reshape(3)
    n = np.linalg.norm(a)
    if not np.isfinite(n) or n < 1e-12:
        raise ValueError(f"axis must be a finite non-zero vector, got {a.tolist()}")
    return tuple(float(x) for x in a / n)  # type: ignore[return-value]


def _vec3(v: Any) -> Vec3:
    a = np.asarray(v, dtype=float).reshape(3)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"vector must be finite, got {a.tolist()}")
    return tuple(float(x) for x in a)  # type: ignore[return-value]


class Articulation(BaseModel):
    """A joint in world coordinates (paper: phi = (t, o, a, rho))."""

    model_config = ConfigDict(frozen=True)

    joint_type: JointType
    axis: Vec3
    origin: Vec3
    lower: float = 0.0
    upper: float = 0.0
    limit_source: str = Field("unset", description="How the limits were set, e.g. 'sweep', 'cap', 'cavity', 'gt'.")

    _axis = field_validator("axis", mode="before")(lambda cls, v: _unit(v))  # noqa: E731
    _origin = field_validator("origin", mode="before")(lambda cls, v: _vec3(v))  # noqa: E731

    def transform(self, q: float) -> np.ndarray:
        """4x4 world transform moving the closed part to joint value ``q``."""
        a = np.asarray(self.axis)
        T = np.eye(4)
        if self.joint_type == "prismatic":
            T[:3, 3] = q * a
            return T
        K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        R = np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * (K @ K)
        o = np.asarray(self.origin)
        T[:3, :3] = R
        T[:3, 3] = o - R @ o
        return T

    def move(self, points: np.ndarray, q: float) -> np.ndarray:
        """Move closed-state points to joint value ``q``."""
        T = self.transform(q)
        return np.asarray(points, float) @ T[:3, :3].T + T[:3, 3]


class OBB(BaseModel):
    """Oriented box: ``axes`` columns u1, u2, u3 with extents s1 >= s2 >= s3 (full side lengths)."""

    model_config = ConfigDict(frozen=True)

    center: Vec3
    axes: tuple[Vec3, Vec3, Vec3] = Field(description="Rows are u1, u2, u3 (unit, right-handed).")
    extents: Vec3

    @property
    def R(self) -> np.ndarray:
        """3x3 matrix whose columns are u1, u2, u3."""
        return np.asarray(self.axes, dtype=float).T

    def contains(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Boolean mask of points inside the box grown by ``margin``."""
        local = (np.asarray(points, float) - np.asarray(self.center)) @ self.R
        return np.all(np.abs(local) <= np.asarray(self.extents) / 2 + margin, axis=1)

    def corners(self) -> np.ndarray:
        """(8,3) corners."""
        s = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float) * np.asarray(self.extents) / 2
        return np.asarray(self.center) + s @ self.R.T


class TopView(BaseModel):
    """A view kept for a part: its frame, the IoU of its mask with the part's rendered silhouette."""

    model_config = ConfigDict(arbitrary_types_allowed=True)

    frame_id: str
    iou: float
    mask: Mask2D | None = Field(None, repr=False)


class PartCandidate(BaseModel):
    """Output of segmentation: one movable-part candidate cut from the scan mesh (full resolution)."""

    model_config = ConfigDict(arbitrary_types_allowed=True)

    candidate_id: int
    label: str = "openable"
    score: float = 1.0
    face_ids: np.ndarray = Field(repr=False, description="Faces of the scan mesh in the part (after clipping).")
    vertex_ids: np.ndarray = Field(repr=False, description="Vertices of the scan mesh in the part.")
    top_views: list[TopView] = Field(default_factory=list)
    seg_frame_id: str | None = Field(None, description="View whose mask produced the segmentation.")
    plane_normal: Vec3 | None = Field(None, description="Clipping plane normal, pointing into the object (away from camera).")
    plane_offset: float | None = Field(None, description="Plane: n . x + d = 0.")
    proposal_face_ids: np.ndarray | None = Field(None, repr=False, description="Faces of the fused 3D proposal (before re-seg).")


class InteractiveObject(BaseModel):
    """One openable object: movable part, joint, box, cavity/base and where they came from."""

    model_config = ConfigDict(frozen=True)

    object_id: str
    label: str = "openable"
    score: float = 1.0
    articulation: Articulation
    initial_articulation: Articulation | None = None
    obb: OBB
    front_normal: Vec3 = Field(description="Unit normal of the front face pointing into the cavity.")
    part_mesh: str = Field(description="Path of the part mesh, relative to the manifest.")
    base_mesh: str | None = None
    inner_mesh: str | None = Field(None, description="Drawer inner box (moves with the part).")
    source_vertex_ids: str | None = Field(None, description="npz with 'vertex_ids' into the input scan mesh.")
    cavity_depth: float | None = None
    cavity_depth_source: str | None = None
    top_views: list[dict[str, Any]] = Field(default_factory=list, description="[{'frame_id', 'iou'}]")
    seg_frame_id: str | None = None


class InteractiveScene(BaseModel):
    """The manifest of a converted scene (``scene.json``); mesh paths are relative to it."""

    model_config = ConfigDict(frozen=True)

    scene_id: str
    input_mesh: str = Field(description="The scan mesh the vertex ids refer to (absolute or relative).")
    background_mesh: str
    objects: list[InteractiveObject] = Field(default_factory=list)
    config: dict[str, Any] = Field(default_factory=dict)
    versions: dict[str, str] = Field(default_factory=dict)
    timings: dict[str, float] = Field(default_factory=dict)
    exports: dict[str, str] = Field(default_factory=dict, description="format -> path relative to the manifest")
    export_sizes: dict[str, int] = Field(
        default_factory=dict, description="bytes of export/: shared 'assets', each format's own files, and 'total'"
    )
    physics: dict[str, Any] | None = Field(
        None, description="Summary of the physics check (react3d_core.physics): per engine its summary line, the verdict; "
        "the full result is in the file it names (physics_check.json)."
    )
    created: str = Field(default_factory=lambda: datetime.now(timezone.utc).isoformat(timespec="seconds"))

    def save(self, path: str | Path) -> Path:
        return write_json(path, self.model_dump(mode="json"))

    @classmethod
    def load(cls, path: str | Path) -> "InteractiveScene":
        path = Path(path)
        if path.is_dir():
            path = path / "scene.json"
        if not path.is_file():
            raise InputError(path, "scene manifest not found")
        try:
            return cls.model_validate(json.loads(path.read_text()))
        except json.JSONDecodeError as exc:
            raise InputError(path, f"scene manifest is not valid JSON ({exc})") from None
        except ValidationError as exc:
            raise InputError(path, f"invalid scene manifest: {exc.errors()[0]['loc']}: {exc.errors()[0]['msg']}") from None


def save_vertex_ids(path: str | Path, vertex_ids: np.ndarray) -> Path:
    return write_npz(path, vertex_ids=np.asarray(vertex_ids, dtype=np.int64))


def load_vertex_ids(path: str | Path) -> np.ndarray:
    z = read_npz(path)
    if "vertex_ids" not in z:
        raise InputError(path, "archive lacks 'vertex_ids'")
    return z["vertex_ids"]
