"""Triangle meshes with vertex colours: load with validation, save atomically (PLY keeps face order)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from .. import geometry
from ..atomic import atomic_path
from ..errors import InputError

_DERIVED = ("face_cross", "face_normals", "face_areas", "face_centroids", "vertex_normals", "edge_adjacency")


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False  # shared by every caller: an in-place edit would corrupt the cache
    return a


@dataclass
class TriMesh:
    """Vertices (N,3 float64, metres), faces (M,3 int64) and vertex colours (N,3 uint8).

    Derived geometry (``face_normals``, ``face_areas``, ``face_centroids``, ``vertex_normals``,
    ``edge_adjacency``) is computed on first use by :mod:`react3d_core.geometry` and cached,
    read-only; assigning ``vertices`` or ``faces`` drops the cache (editing them in place does not:
    build a new mesh instead). Pickles and copies leave the cache out.
    """

    vertices: np.ndarray
    faces: np.ndarray
    colors: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.vertices = np.asarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.asarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if self.colors is None:
            self.colors = np.full((len(self.vertices), 3), 180, np.uint8)
        self.colors = np.asarray(self.colors)
        if self.colors.dtype != np.uint8:
            c = self.colors.astype(float)
            if c.size and c.max() <= 1.0:
                c = c * 255.0
            self.colors = np.clip(np.round(c), 0, 255).astype(np.uint8)
        self.colors = self.colors[:, :3].reshape(-1, 3)

    def __setattr__(self, name: str, value: Any) -> None:
        if name in ("vertices", "faces"):
            for key in _DERIVED:
                self.__dict__.pop(key, None)
        object.__setattr__(self, name, value)

    def __getstate__(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if k not in _DERIVED}

    @cached_property
    def face_cross(self) -> np.ndarray:
        """(M,3) ``(v1 - v0) x (v2 - v0)``: right-hand normal times twice the area."""
        return _frozen(geometry.triangle_cross(self.vertices, self.faces))

    @cached_property
    def face_normals(self) -> np.ndarray:
        """(M,3) unit face normals (degenerate faces: ``geometry.NORMAL_FLOOR``)."""
        return _frozen(geometry.unit_normals(self.face_cross))

    @cached_property
    def face_areas(self) -> np.ndarray:
        """(M,) face areas (m^2)."""
        return _frozen(0.5 * np.linalg.norm(self.face_cross, axis=1))

    @cached_property
    def face_centroids(self) -> np.ndarray:
        """(M,3) face centroids (mean of the three corners)."""
        return _frozen(self.vertices[self.faces].mean(1))

    @cached_property
    def vertex_normals(self) -> np.ndarray:
        """(N,3) area-weighted unit vertex normals."""
        return _frozen(geometry.vertex_normals(self.vertices, self.faces, self.face_cross))

    @cached_property
    def edge_adjacency(self) -> np.ndarray:
        """(E,2) pairs ``i < j`` of faces sharing an edge of this mesh's own vertex ids (unwelded)."""
        return _frozen(geometry.edge_adjacency(self.faces))

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    def bounds(self) -> np.ndarray:
        """(2,3) min/max corner."""
        if not len(self.vertices):
            return np.zeros((2, 3))
        return np.stack([self.vertices.min(0), self.vertices.max(0)])

    def submesh(self, face_ids: np.ndarray) -> tuple["TriMesh", np.ndarray]:
        """Mesh made of ``face_ids``; also returns the kept original vertex indices."""
        faces = self.faces[np.asarray(face_ids, dtype=np.int64)]
        vids, inv = np.unique(faces.ravel(), return_inverse=True)
        return TriMesh(self.vertices[vids], inv.reshape(-1, 3), self.colors[vids]), vids

    def to_trimesh(self):  # noqa: ANN201 - optional heavy type
        import trimesh

        return trimesh.Trimesh(self.vertices, self.faces, vertex_colors=self.colors, process=False)

    def to_open3d(self):  # noqa: ANN201
        import open3d as o3d

        m = o3d.geometry.TriangleMesh(
            o3d.utility.Vector3dVector(self.vertices), o3d.utility.Vector3iVector(self.faces.astype(np.int32))
        )
        m.vertex_colors = o3d.utility.Vector3dVector(self.colors.astype(np.float64) / 255.0)
        return m


def load_mesh(path: str | Path) -> TriMesh:
    """Read a PLY/OBJ/GLB mesh keeping vertex and face order; clear error on bad input."""
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise InputError(path, "mesh file not found")
    try:
        loaded = trimesh.load(path, process=False, force="mesh")
    except Exception as exc:  # noqa: BLE001
        raise InputError(path, f"cannot read mesh ({exc.__class__.__name__}: {exc})") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise InputError(path, "mesh has no triangles")
    v = np.asarray(loaded.vertices, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise InputError(path, f"mesh has {int((~np.isfinite(v)).any(1).sum())} vertices with NaN/inf coordinates")
    f = np.asarray(loaded.faces, dtype=np.int64)
    if f.min() < 0 or f.max() >= len(v):
        raise InputError(path, "mesh faces index vertices that do not exist")
    colors = None
    try:
        vc = loaded.visual.vertex_colors  # type: ignore[attr-defined]
        if vc is not None and len(vc) == len(v):
            colors = np.asarray(vc)[:, :3]
    except Exception:  # noqa: BLE001 - texture-only visuals: fall back to grey
        colors = None
    return TriMesh(v, f, colors)


def save_mesh(path: str | Path, mesh: TriMesh) -> Path:
    """Write a binary PLY (or any trimesh format by suffix) atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:
        mesh.to_trimesh().export(tmp, file_type=path.suffix.lstrip(".") or "ply")
    return path
