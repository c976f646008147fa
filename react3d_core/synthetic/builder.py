"""Assemble a scan-like triangle mesh from subdivided boxes, remembering which faces belong to which part.

Scanned meshes have roughly uniform triangle sizes (a few cm), so every box face is split into a grid
of ~``edge`` sized quads; GT ``triIndices`` then index a realistic number of faces per part. Face order
is the insertion order, so the same build always yields the same face ids.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.mesh import TriMesh
from ..geometry import concat_meshes
from .materials import MATTE

# The six faces of a unit cube as (normal axis, sign); grids are emitted per face so each face has
# its own vertices (like a scan, faces of different planes are not welded).
_FACES = [(0, -1), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1)]


def _grid(n_u: int, n_v: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit-square grid vertices (u, v) and its triangles, counter-clockwise in (u, v)."""
    u, v = np.meshgrid(np.linspace(0.0, 1.0, n_u + 1), np.linspace(0.0, 1.0, n_v + 1), indexing="xy")
    uv = np.stack([u.ravel(), v.ravel()], 1)
    i, j = np.meshgrid(np.arange(n_u), np.arange(n_v), indexing="xy")
    a = (j * (n_u + 1) + i).ravel()
    b, c, d = a + 1, a + n_u + 2, a + n_u + 1
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return uv, tris


def box_mesh(lo: np.ndarray, hi: np.ndarray, edge: float, skip: tuple[tuple[int, int], ...] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box [lo, hi] with outward faces subdivided to ~``edge``; ``skip`` omits faces (axis, sign)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    size = hi - lo
    pieces = []
    for axis, sign in _FACES:
        if (axis, sign) in skip:
            continue
        a1, a2 = [(axis + 1) % 3, (axis + 2) % 3]
        nu = max(1, int(np.ceil(size[a1] / edge)))
        nv = max(1, int(np.ceil(size[a2] / edge)))
        uv, tris = _grid(nu, nv)
        p = np.empty((len(uv), 3))
        p[:, axis] = hi[axis] if sign > 0 else lo[axis]
        p[:, a1] = lo[a1] + uv[:, 0] * size[a1]
        p[:, a2] = lo[a2] + uv[:, 1] * size[a2]
        # (a1, a2, axis) is right-handed, so CCW in (u, v) faces +axis; flip for the -axis face.
        if sign < 0:
            tris = tris[:, ::-1]
        pieces.append((p, tris))
    return concat_meshes(pieces)


@dataclass
class MeshBuilder:
    """Collects pieces (vertices, faces, colour) under part keys and merges them in insertion order."""

    edge: float = 0.03
    seed: int = 0
    _verts: list[np.ndarray] = field(default_factory=list)
    _faces: list[np.ndarray] = field(default_factory=list)
    _cols: list[np.ndarray] = field(default_factory=list)
    _keys: list[np.ndarray] = field(default_factory=list)
    _mats: list[np.ndarray] = field(default_factory=list)
    _base: list[np.ndarray] = field(default_factory=list)
    _n: int = 0
    _key_ids: dict[str, int] = field(default_factory=dict)

    def key_id(self, key: str | None) -> int:
        """Integer id of a part key (-1 for geometry that belongs to no part)."""
        if key is None:
            return -1
        return self._key_ids.setdefault(key, len(self._key_ids))

    def add(self, verts: np.ndarray, faces: np.ndarray, color: tuple[int, int, int], key: str | None = None,
            transform: np.ndarray | None = None, noise: float = 6.0, material: int = MATTE) -> None:
        """Add a piece; ``transform`` (4x4) places it in the world; colours get a little per-vertex noise.

        ``material`` (see :mod:`.materials`) only drives the photo-realistic renderer; it changes no geometry."""
        if transform is not None:
            verts = verts @ transform[:3, :3].T + transform[:3, 3]
        rng = np.random.default_rng(self.seed * 7919 + len(self._verts))
        col = np.clip(np.asarray(color, float)[None] + rng.normal(0.0, noise, (len(verts), 3)), 0, 255)
        self._verts.append(verts)
        self._faces.append(faces + self._n)
        self._cols.append(col.astype(np.uint8))
        self._keys.append(np.full(len(faces), self.key_id(key), np.int32))
        self._mats.append(np.full(len(faces), material, np.uint8))
        self._base.append(np.broadcast_to(np.asarray(color, np.uint8)[None], (len(faces), 3)))
        self._n += len(verts)

    def add_box(self, lo, hi, color, key: str | None = None, transform: np.ndarray | None = None,  # noqa: ANN001
                skip: tuple[tuple[int, int], ...] = (), material: int = MATTE) -> None:
        v, f = box_mesh(np.asarray(lo, float), np.asarray(hi, float), self.edge, skip)
        self.add(v, f, color, key, transform, material=material)

    def build(self) -> tuple[TriMesh, np.ndarray, dict[str, int]]:
        """The merged mesh, the part-key id of every face (-1 = none) and the key -> id table."""
        mesh = TriMesh(np.concatenate(self._verts), np.concatenate(self._faces), np.concatenate(self._cols))
        return mesh, np.concatenate(self._keys), dict(self._key_ids)

    def materials(self) -> np.ndarray:
        """Material id of every face, in the order of :meth:`build`."""
        return np.concatenate(self._mats) if self._mats else np.zeros(0, np.uint8)

    def base_colors(self) -> np.ndarray:
        """The colour each face was added with (no per-vertex noise): the photo renderer's albedo."""
        return np.concatenate(self._base) if self._base else np.zeros((0, 3), np.uint8)


def bisect_to_size(verts: np.ndarray, faces: np.ndarray, edge: float, max_iter: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Split every triangle at the midpoint of its longest edge until all edges are <= ``edge``.

    Unlike uniform 1-to-4 subdivision, long thin triangles (box primitives) are only split across
    their length, so the face count follows the surface area. New vertices are not shared with the
    neighbouring triangle (T-junctions lie exactly on the neighbour's edge, so no cracks appear).
    """
    v = np.asarray(verts, float)
    f = np.asarray(faces, np.int64)
    for _ in range(max_iter):
        p = v[f]
        lens = np.linalg.norm(p[:, [1, 2, 0]] - p, axis=2)  # edge k runs from corner k to corner k+1
        k = lens.argmax(1)
        split = lens[np.arange(len(f)), k] > edge
        if not split.any():
            break
        fs, ks = f[split], k[split]
        a = fs[np.arange(len(fs)), ks]
        b = fs[np.arange(len(fs)), (ks + 1) % 3]
        c = fs[np.arange(len(fs)), (ks + 2) % 3]
        mid = np.arange(len(v), len(v) + len(fs))
        v = np.concatenate([v, 0.5 * (v[a] + v[b])])
        # (a, mid, c) and (mid, b, c) keep the winding of (a, b, c)
        f = np.concatenate([f[~split], np.stack([a, mid, c], 1), np.stack([mid, b, c], 1)])
    return v, f
