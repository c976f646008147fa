"""Mesh connectivity that tolerates unwelded scans: weld close vertices, face adjacency, components.

Scanned (and synthetic, per-object) meshes often repeat vertices along seams, so two faces are
"connected" when they share a vertex after merging vertices closer than ``weld_m``.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..data.mesh import TriMesh
from ..raster import Rasterizer


def weld_labels(vertices: np.ndarray, weld_m: float) -> np.ndarray:
    """Label per vertex; vertices closer than ``weld_m`` (transitively) share a label."""
    n = len(vertices)
    if n == 0 or weld_m <= 0:
        return np.arange(n)
    pairs = cKDTree(vertices).query_pairs(weld_m, output_type="ndarray")
    if not len(pairs):
        return np.arange(n)
    g = sparse.coo_matrix((np.ones(len(pairs), np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    return connected_components(g, directed=False)[1]


def welded_faces(mesh: TriMesh, weld_m: float) -> np.ndarray:
    """Faces re-indexed into welded vertex labels (M,3)."""
    return weld_labels(mesh.vertices, weld_m)[mesh.faces]


def face_components(wfaces: np.ndarray, face_ids: np.ndarray) -> tuple[int, np.ndarray]:
    """Connected components of the faces ``face_ids`` (shared welded vertex = connected)."""
    face_ids = np.asarray(face_ids, np.int64)
    if not len(face_ids):
        return 0, np.zeros(0, np.int64)
    v, inv = np.unique(wfaces[face_ids].ravel(), return_inverse=True)
    nf, nv = len(face_ids), len(v)
    rows = np.repeat(np.arange(nf), 3)
    b = sparse.coo_matrix((np.ones(3 * nf, np.int8), (rows, nf + inv.ravel())), shape=(nf + nv, nf + nv))
    n, lab = connected_components(b, directed=False)
    lab = lab[:nf]
    _, lab = np.unique(lab, return_inverse=True)
    return int(lab.max()) + 1, lab


def surface_distance(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Exact distance from each point to the surface of ``triangles`` (T,3,3) (Rasterizer, Embree)."""
    v = triangles.reshape(-1, 3)
    return Rasterizer(TriMesh(v, np.arange(len(v)).reshape(-1, 3))).distance(points)


def largest_component(mesh: TriMesh, wfaces: np.ndarray, face_ids: np.ndarray, attach_m: float = 0.0,
                      keep_share: float = 1.0) -> np.ndarray:
    """Faces of the largest (by area) component, plus components within ``attach_m`` of it and
    components holding at least ``keep_share`` of the faces' area (1: none).

    Why the attachment: a handle modelled or scanned as a separate shell touching the door
    surface shares no vertex with it, yet moves with it. Why the share: a glass door's frame whose
    thin rails the scan (or the fusion mesh's decimation) broke is two stiles a pane apart, each
    about half the door; the largest alone is a sliver no view's mask matches.
    """
    face_ids = np.unique(np.asarray(face_ids, np.int64))
    n, lab = face_components(wfaces, face_ids)
    if n <= 1:
        return face_ids
    tri = mesh.vertices[mesh.faces[face_ids]]
    area = np.bincount(lab, weights=mesh.face_areas[face_ids], minlength=n)
    big = int(np.argmax(area))
    keep = lab == big
    if keep_share < 1.0:
        keep |= np.isin(lab, np.flatnonzero(area >= keep_share * area.sum()))
    if attach_m > 0 and not keep.all():
        d = surface_distance(tri[keep], tri[~keep].reshape(-1, 3)).reshape(-1, 3)
        near_comp = np.unique(lab[~keep][(d <= attach_m).any(1)])
        keep |= np.isin(lab, near_comp)
    return face_ids[keep]
