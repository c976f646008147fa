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


def _orient(p: np.ndarray, tris: np.ndarray, want: np.ndarray) -> np.ndarray:
    """``tris`` with each triangle's winding flipped where its normal points against ``want`` (per face)."""
    n = np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
    flip = (n * want).sum(1) < 0
    out = tris.copy()
    out[flip] = tris[flip][:, ::-1]
    return out


def cylinder_mesh(cx: float, cz: float, y0: float, y1: float, r_out: float, edge: float,
                  r_in: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A disc (``r_in`` = 0) or ring of radius ``r_out`` whose axis runs along y from ``y0`` to ``y1``
    (a round door or window facing -y in a wall frame), centred at (cx, cz); faces ~``edge``, outward."""
    n_t = max(12, int(np.ceil(2 * np.pi * r_out / edge)))
    th = np.linspace(0.0, 2 * np.pi, n_t, endpoint=False)
    ring = np.stack([np.cos(th), np.sin(th)], 1)
    n_r = max(1, int(np.ceil((r_out - r_in) / edge)))
    radii = np.linspace(r_in, r_out, n_r + 1)
    pieces = []
    j = np.arange(n_t)
    jn = (j + 1) % n_t

    def strip(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Quads between two rings of ``n_t`` vertices (indices a, b)."""
        return np.concatenate([np.stack([a[j], a[jn], b[jn]], 1), np.stack([a[j], b[jn], b[j]], 1)])

    for y, sign in ((y0, -1.0), (y1, 1.0)):  # caps
        rs = radii[1:] if r_in == 0.0 else radii
        pts = [np.array([[cx, y, cz]])] if r_in == 0.0 else []
        pts += [np.c_[cx + r * ring[:, 0], np.full(n_t, y), cz + r * ring[:, 1]] for r in rs]
        p = np.concatenate(pts)
        off = 1 if r_in == 0.0 else 0
        tris = []
        if r_in == 0.0:
            tris.append(np.stack([np.zeros(n_t, int), 1 + j, 1 + jn], 1))
        for k in range(len(rs) - 1):
            tris.append(strip(off + k * n_t + np.arange(n_t), off + (k + 1) * n_t + np.arange(n_t)))
        t = np.concatenate(tris)
        pieces.append((p, _orient(p, t, np.array([0.0, sign, 0.0])[None])))
    n_y = max(1, int(np.ceil(abs(y1 - y0) / edge)))
    for r, out in ((r_out, 1.0), (r_in, -1.0)):  # outer and inner walls
        if r <= 0.0:
            continue
        ys = np.linspace(y0, y1, n_y + 1)
        p = np.concatenate([np.c_[cx + r * ring[:, 0], np.full(n_t, y), cz + r * ring[:, 1]] for y in ys])
        t = np.concatenate([strip(k * n_t + np.arange(n_t), (k + 1) * n_t + np.arange(n_t)) for k in range(n_y)])
        c = p[t].mean(1)
        want = out * np.c_[c[:, 0] - cx, np.zeros(len(c)), c[:, 2] - cz]
        pieces.append((p, _orient(p, t, want)))
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

    def add_cylinder(self, cx: float, cz: float, y0: float, y1: float, r_out: float, color, key: str | None = None,  # noqa: ANN001
                     transform: np.ndarray | None = None, r_in: float = 0.0, material: int = MATTE) -> None:
        """A disc or ring along y (see :func:`cylinder_mesh`)."""
        v, f = cylinder_mesh(cx, cz, y0, y1, r_out, self.edge, r_in)
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
