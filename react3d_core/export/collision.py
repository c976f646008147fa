"""Collision geometry: convex pieces for moving/fixed-base bodies, planar patches for MuJoCo's background.

Simulators turn one concave mesh into its convex hull (a drawer becomes a solid block), so every
body gets a list of convex pieces, each written as its own collision element:
- a connected component that is already convex (a box wall of a generated base, a watertight box)
  is kept as its hull: the direct, exact and cheap decomposition of box-like bases;
- an open scan surface (a door or drawer front) has no inside to decompose: its hull is used;
- a watertight concave component goes through CoACD (capped at the remaining piece budget).
Pieces thinner than ``min_collision_thickness`` become boxes that thick (a flat scan has no volume).
"""

from __future__ import annotations

import hashlib
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import trimesh

from ..atomic import atomic_path
from ..data.mesh import TriMesh
from ..npyio import load_npz

MAX_HULL_VERTICES = 200  # PhysX caps a hull at 255 vertices by default


@dataclass
class ConvexPiece:
    """A closed convex triangle mesh (outward faces), world coordinates."""

    vertices: np.ndarray
    faces: np.ndarray
    source: str  # "component", "hull", "coacd", "box", "patch"
    box: np.ndarray | None = None  # (15,) centre, rotation (3x3, row-major; columns are the box axes), extents: an exact box

    @cached_property
    def volume(self) -> float:
        return float(trimesh.Trimesh(self.vertices, self.faces, process=False).volume)

    @cached_property
    def axes(self) -> np.ndarray:
        """Its face-normal directions, duplicates and opposites removed (3 for a box)."""
        from .clearance import unique_axes

        v, f = self.vertices, self.faces
        n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
        return unique_axes(n[np.linalg.norm(n, axis=1) > 1e-12], tol=1e-5)

    @cached_property
    def centre(self) -> np.ndarray:
        """Centre of its bounding box: writers store the vertices relative to it and place the file there.

        Why: PhysX (SAPIEN, Isaac Sim) cooks a convex mesh in the coordinates of its file; a hull of a few
        mm whose vertices lie metres from that origin got contacts 1-2 cm deep with a neighbour 4 mm away
        (a flap blew up in SAPIEN only). Near its own origin the same hull collides exactly."""
        return (self.vertices.min(0) + self.vertices.max(0)) / 2

    def box_frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centre, rotation, extents) of a box piece (writers emit it as a box primitive)."""
        assert self.box is not None
        return self.box[:3], self.box[3:12].reshape(3, 3), self.box[12:]


def _pca_frame(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre, axes (columns, right-handed) and extents of the PCA box of ``points`` (robust to flat sets)."""
    c = points.mean(0)
    _, _, vt = np.linalg.svd(points - c, full_matrices=False)
    R = vt.T if vt.shape[0] == 3 else np.eye(3)
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    local = (points - c) @ R
    lo, hi = local.min(0), local.max(0)
    return c + R @ ((lo + hi) / 2), R, hi - lo


def _box_from_points(points: np.ndarray, min_thickness: float) -> tuple[np.ndarray, np.ndarray]:
    """PCA box of ``points`` with every extent at least ``min_thickness``."""
    c, R, ext = _pca_frame(points)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = c
    box = trimesh.creation.box(extents=np.maximum(ext, min_thickness), transform=T)
    return np.asarray(box.vertices), np.asarray(box.faces)


def convex_piece(points: np.ndarray, min_thickness: float, source: str) -> ConvexPiece:
    """Convex hull of ``points`` (low-poly, at least ``min_thickness`` thick)."""
    pts = np.unique(np.asarray(points, float), axis=0)
    if len(pts) == 0:
        raise ValueError("no points for a convex piece")
    if len(pts) >= 4 and np.min(_pca_frame(pts)[2]) >= min_thickness:
        hull = trimesh.Trimesh(pts, process=False).convex_hull
        k = 16
        while len(hull.vertices) > MAX_HULL_VERTICES:
            cell = np.ptp(hull.vertices, 0).max() / k
            snapped = np.unique(np.round(hull.vertices / cell) * cell, axis=0)
            hull = trimesh.Trimesh(snapped, process=False).convex_hull
            k = max(2, k // 2)
        return ConvexPiece(np.asarray(hull.vertices), np.asarray(hull.faces), source)
    v, f = _box_from_points(pts, min_thickness)
    return ConvexPiece(v, f, "box")


def _components(mesh: TriMesh) -> list[trimesh.Trimesh]:
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    tm.merge_vertices()
    parts = tm.split(only_watertight=False)
    return sorted(parts, key=lambda p: -float(np.prod(np.ptp(p.vertices, 0) + 1e-3)))


def convex_pieces(mesh: TriMesh, max_pieces: int = 16, min_thickness: float = 0.005, convex_tol: float = 0.02) -> list[ConvexPiece]:
    """Decompose ``mesh`` into at most ``max_pieces`` convex pieces (see module doc for the rules)."""
    if mesh.n_faces == 0:
        return []
    comps = _components(mesh)
    if len(comps) > max_pieces:  # many fragments: keep the largest, hull the rest together
        rest = np.vstack([c.vertices for c in comps[max_pieces - 1 :]])
        comps = comps[: max_pieces - 1]
        extra = [convex_piece(rest, min_thickness, "hull")]
    else:
        extra = []
    pieces: list[ConvexPiece] = []
    budget = max_pieces - len(extra)
    for i, comp in enumerate(comps):
        left = budget - len(pieces) - (len(comps) - i - 1)
        with np.errstate(invalid="ignore", divide="ignore"):  # a closed but flat component: volume 0, centre 0 / 0
            solid = comp.is_watertight and comp.volume > 0
        if solid:
            hull_vol = comp.convex_hull.volume
            if comp.volume >= (1 - convex_tol) * hull_vol or left <= 1:
                pieces.append(convex_piece(comp.vertices, min_thickness, "component"))
                continue
            pieces.extend(_coacd(comp, left, min_thickness))
        else:
            pieces.append(convex_piece(comp.vertices, min_thickness, "hull"))
    return pieces + extra


def _coacd(comp: trimesh.Trimesh, max_pieces: int, min_thickness: float) -> list[ConvexPiece]:
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(comp.vertices), np.asarray(comp.faces)), threshold=0.05, max_convex_hull=max_pieces, seed=0,
        max_ch_vertex=MAX_HULL_VERTICES,
    )
    return [convex_piece(np.asarray(v), min_thickness, "coacd") for v, _ in parts]


def _fit_slabs(tri: np.ndarray, n: np.ndarray, cell: float, min_thickness: float, slab: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One slab box per group of triangles (grid cell of the centroid x dominant normal direction).

    Returns per group: corners (G,8,3), axes (G,3,3) (rows: normal, two in-plane axes), the
    surface's own thickness along the normal (G,), per triangle its group (T,), and the boxes
    (G,15) as ``ConvexPiece.box``. The normal
    points out of the surface (the side its faces face) and the slab lies behind the surface:
    its outer face is the outermost point of the surface, so a surface's collider never stands
    in front of it, and is at least ``slab`` thick. In-plane extents below ``min_thickness`` are padded
    symmetrically."""
    axis = np.argmax(np.abs(n), axis=1)
    direction = axis * 2 + (n[np.arange(len(n)), axis] > 0)
    cells = np.floor(tri.mean(1) / cell).astype(np.int64)
    _, g_tri = np.unique(np.column_stack([cells, direction]), axis=0, return_inverse=True)
    g_tri = g_tri.ravel()
    g = np.repeat(g_tri, 3)
    P = tri.reshape(-1, 3)
    G = int(g.max()) + 1
    cnt = np.bincount(g, minlength=G).astype(float)
    mu = np.stack([np.bincount(g, P[:, k], G) for k in range(3)], 1) / cnt[:, None]
    D = P - mu[g]
    cov = np.empty((G, 3, 3))
    for a in range(3):
        for b in range(a, 3):
            cov[:, a, b] = cov[:, b, a] = np.bincount(g, D[:, a] * D[:, b], G) / cnt
    _, E = np.linalg.eigh(cov)
    nrm = E[:, :, 0]  # smallest variance: the patch normal
    facing = np.stack([np.bincount(g_tri, n[:, k], G) for k in range(3)], 1)  # area-weighted face normals
    nrm = nrm * np.where(np.sum(nrm * facing, 1) < 0, -1.0, 1.0)[:, None]
    # in-plane axes follow the grid (the world axis most perpendicular to the normal), so square
    # cells give tight boxes; PCA's in-plane axes are arbitrary for a square and overshoot by 41 %
    k = np.argmin(np.abs(nrm), axis=1)
    u = np.eye(3)[k] - np.sum(np.eye(3)[k] * nrm, 1, keepdims=True) * nrm
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    R = np.stack([nrm, u, np.cross(nrm, u)], axis=2)
    local = np.einsum("pk,pkj->pj", D, R[g])
    order = np.argsort(g, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(g[order]) != 0])
    lo = np.minimum.reduceat(local[order], starts, axis=0)
    hi = np.maximum.reduceat(local[order], starts, axis=0)
    thickness = hi[:, 0] - lo[:, 0]
    lo[:, 0] = np.minimum(lo[:, 0], hi[:, 0] - slab)  # behind the surface
    pad = np.maximum(min_thickness - (hi[:, 1:] - lo[:, 1:]), 0) / 2
    lo[:, 1:] -= pad
    hi[:, 1:] += pad
    unit = np.asarray(trimesh.creation.box(extents=(1.0, 1.0, 1.0)).vertices) + 0.5  # corners in [0, 1]^3
    local_corners = lo[:, None, :] + unit[None] * (hi - lo)[:, None, :]
    corners = mu[:, None, :] + np.einsum("gcj,gij->gci", local_corners, R)
    centre = mu + np.einsum("gij,gj->gi", R, (lo + hi) / 2)
    boxes = np.concatenate([centre, R.reshape(G, 9), hi - lo], axis=1)
    return corners, np.transpose(R, (0, 2, 1)), thickness, g_tri, boxes


def _slab_pieces(corners: np.ndarray, boxes: np.ndarray) -> list[ConvexPiece]:
    faces = np.asarray(trimesh.creation.box(extents=(1.0, 1.0, 1.0)).faces)
    return [ConvexPiece(c, faces, "patch", b) for c, b in zip(corners, boxes)]


def planar_patches(mesh: TriMesh, cell: float, min_thickness: float, min_cell: float | None = None,
                   flatness: float | None = None, obstacles: Sequence = (), margin: float = 0.0,
                   faces: np.ndarray | None = None, extra: np.ndarray | None = None, slab: float | None = None) -> list[ConvexPiece]:
    """Static background for engines that convexify every collision mesh (MuJoCo, PyBullet child links).

    Faces are grouped by the grid cell of their centroid and by dominant normal direction (+-x, +-y,
    +-z); each group becomes a slab box behind its surface (at least ``slab`` thick, default
    ``min_thickness``), so
    floors and walls become slabs and a corner never becomes a solid wedge. All groups are fitted
    at once (batched covariance / eigh / segment min-max).

    Refinement (``min_cell`` given): a slab thicker than ``flatness`` (several parallel surfaces in
    one cell: a front and the wall behind it) is refitted from its faces in cells half as large, down
    to 4 x ``min_cell``; one within ``margin`` of an obstacle (``clearance.Obstacle``: a part's path, a
    cavity) is cut back (``clearance.keep_clear``) if that keeps ``REFINE_KEEP`` of it, else refitted
    too (at ``min_cell``, cut back whatever it keeps).
    ``faces``: indices of the faces to use (default all); ``extra``: more triangles (k,3,3).
    """
    from .clearance import ObstacleSet, box_conflicts, keep_clear

    f = mesh.faces if faces is None else mesh.faces[np.asarray(faces, np.int64)]
    tri = mesh.vertices[f]
    if extra is not None and len(extra):
        tri = np.concatenate([tri, np.asarray(extra, float)])
    if not len(tri):
        return []
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    keep = np.linalg.norm(n, axis=1) > 1e-15
    tri, n = tri[keep], n[keep]
    if not len(tri):
        return []
    out: list[ConvexPiece] = []
    obs = ObstacleSet(obstacles)
    size = cell
    while len(tri):
        corners, axes, thickness, g_tri, boxes = _fit_slabs(tri, n, size, min_thickness, min_thickness if slab is None else slab)
        last = min_cell is None or size / 2 < min_cell
        # parallel surfaces are told apart down to 4 x min_cell (a front frame and the wall behind it);
        # only obstacles refine further (a slab standing across a gap that a part moves through)
        split = np.zeros(len(corners), bool) if last or flatness is None or size / 2 < 4 * min_cell else thickness > flatness
        near = box_conflicts(corners, axes, obstacles, margin) if len(obstacles) else np.zeros(len(corners), bool)
        out += _slab_pieces(corners[~split & ~near], boxes[~split & ~near])
        for g in np.flatnonzero(near & ~split):  # cut back; refine instead where a cut would lose much
            (piece,) = _slab_pieces(corners[g : g + 1], boxes[g : g + 1])
            cut, _ = keep_clear([piece], obs, margin)
            if last or sum(c.volume for c in cut) >= REFINE_KEEP * piece.volume:
                out += cut
            else:
                split[g] = True
        if last or not split.any():
            break
        sel = split[g_tri]
        tri, n = tri[sel], n[sel]
        size /= 2
    return out


REFINE_KEEP = 0.7
"""A background slab near an obstacle is cut back when that keeps this share of it, else refitted in smaller cells."""


COLLISION_VERSION = "3"
"""Bump when convex_pieces / planar_patches change their output: it is part of the cache key."""


def _cache_key(kind: str, mesh: TriMesh, params: tuple) -> str:  # noqa: ANN401
    h = hashlib.sha256(f"{kind}|{COLLISION_VERSION}|{params!r}|{len(mesh.vertices)}|{len(mesh.faces)}".encode())
    h.update(np.ascontiguousarray(mesh.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, np.int64).tobytes())
    return h.hexdigest()


def cached_pieces(cache_dir: str | Path | None, kind: str, mesh: TriMesh, params: tuple,
                  compute: Callable[[], list[ConvexPiece]]) -> list[ConvexPiece]:
    """``compute()`` keyed by the mesh's content and ``params`` in ``cache_dir`` (None: no cache).

    Why: CoACD and the background patches depend only on the geometry and a few settings, so a
    re-export (other formats, other texture budget) reads them back instead of recomputing. A file
    that cannot be read is recomputed and rewritten (atomic write: never a half file)."""
    if cache_dir is None:
        return compute()
    key = _cache_key(kind, mesh, params)
    path = Path(cache_dir) / key[:2] / f"{kind}-{key}.npz"
    if path.is_file():
        try:
            z = load_npz(path)
            counts_v, counts_f = z["counts_v"], z["counts_f"]
            vs = np.split(z["vertices"], np.cumsum(counts_v)[:-1]) if len(counts_v) else []
            fs = np.split(z["faces"], np.cumsum(counts_f)[:-1]) if len(counts_f) else []
            boxes = z["boxes"] if "boxes" in z else np.full((len(vs), 15), np.nan)
            return [ConvexPiece(v, f, str(s), None if np.isnan(b).any() else b) for v, f, s, b in zip(vs, fs, z["sources"], boxes)]
        except (OSError, ValueError, KeyError, zipfile.BadZipFile):
            pass  # unreadable: recompute below and overwrite
    pieces = compute()
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(
                fh,
                vertices=np.concatenate([p.vertices for p in pieces]) if pieces else np.zeros((0, 3)),
                faces=np.concatenate([p.faces for p in pieces]) if pieces else np.zeros((0, 3), np.int64),
                counts_v=np.array([len(p.vertices) for p in pieces], np.int64),
                counts_f=np.array([len(p.faces) for p in pieces], np.int64),
                sources=np.array([p.source for p in pieces], dtype=str),
                boxes=np.array([p.box if p.box is not None else np.full(15, np.nan) for p in pieces]).reshape(-1, 15),
            )
    return pieces
