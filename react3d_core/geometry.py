"""The geometry kernel: triangle quantities, face adjacency and vertex-set overlaps, derived one way.

:class:`~react3d_core.data.mesh.TriMesh` caches the per-mesh quantities (``face_normals``,
``face_areas``, ``face_centroids``, ``vertex_normals``, ``edge_adjacency``) by calling these
functions once; code that holds raw arrays (welded faces, hull simplices, a box being built) calls
them directly. Ray casting lives in :class:`react3d_core.raster.Rasterizer`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy import sparse

NORMAL_FLOOR = 1e-15
"""Unit normals divide by max(|cross|, NORMAL_FLOOR): a degenerate face (|cross| < 1e-15, an area
below 5e-16 m^2) gets a normal of length < 1 (zero when its corners coincide), never a made-up
direction."""


def triangle_cross(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(M,3) ``(v1 - v0) x (v2 - v0)`` per face: the right-hand normal scaled by twice the area."""
    v = np.asarray(vertices)
    f = np.asarray(faces)
    if not len(f):
        return np.zeros((0, 3))
    return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])


def triangle_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(M,) triangle areas."""
    return 0.5 * np.linalg.norm(triangle_cross(vertices, faces), axis=1)


def unit_normals(cross: np.ndarray) -> np.ndarray:
    """Unit normals from :func:`triangle_cross` (degenerate faces: see ``NORMAL_FLOOR``)."""
    return cross / np.maximum(np.linalg.norm(cross, axis=1), NORMAL_FLOOR)[:, None]


def horizontal_right(n: np.ndarray) -> np.ndarray:
    """Unit ``z x n``: the horizontal axis to the right of a viewer facing a vertical surface whose
    (horizontal) normal ``n`` points back at them (z up)."""
    u = np.cross([0.0, 0.0, 1.0], n)
    return u / np.linalg.norm(u)


def weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """The value at which the weights sorted by value reach half their sum (the lower one on a tie): an
    area-weighted median, which a few large faces or a handle cannot pull the way a mean is pulled."""
    v, w = np.asarray(values, float), np.asarray(weights, float)
    order = np.argsort(v, kind="stable")
    half = np.searchsorted(np.cumsum(w[order]), 0.5 * w.sum())
    return float(v[order][min(half, len(v) - 1)])


def concat_meshes(pieces: Sequence[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """One (vertices, faces) from pieces ``(vertices_i, faces_i)``, each piece's faces offset past the
    vertices before it."""
    offsets = np.cumsum([0] + [len(v) for v, _ in pieces[:-1]])
    return np.concatenate([v for v, _ in pieces]), np.concatenate([f + o for (_, f), o in zip(pieces, offsets)])


def vertex_normals(vertices: np.ndarray, faces: np.ndarray, cross: np.ndarray | None = None) -> np.ndarray:
    """(N,3) area-weighted unit vertex normals (sum of the adjacent faces' cross products);
    ``cross`` (optional) is :func:`triangle_cross` already computed."""
    n_v = len(vertices)
    fn = triangle_cross(vertices, faces) if cross is None else cross
    idx = np.asarray(faces).ravel()
    rep = np.repeat(fn, 3, axis=0)
    n = np.stack([np.bincount(idx, rep[:, k], minlength=n_v) for k in range(3)], 1) if len(idx) else np.zeros((n_v, 3))
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def edge_adjacency(faces: np.ndarray, chain: str = "face") -> np.ndarray:
    """(E,2) unique pairs ``i < j`` of faces sharing an undirected edge (pass welded faces to join
    faces across duplicated seam vertices).

    An edge of ``k > 2`` faces (non-manifold: touching boxes, welded seams) gives the ``k - 1`` pairs
    of a chain through them, not all ``k (k - 1) / 2``; ``chain`` is the chain's order: ``"face"``
    by face id (fusion, ``TriMesh.edge_adjacency``) or ``"corner"`` by the edge's corner slot
    ((0,1) of every face, then (1,2), then (2,0)), then face id (planar facets). The two differ only
    on non-manifold edges, where a chain decides which face pairs are then compared.
    """
    faces = np.asarray(faces)
    m = len(faces)
    if m == 0:
        return np.zeros((0, 2), np.int64)
    if chain == "face":
        e = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], 1).reshape(-1, 2)
        fid = np.repeat(np.arange(m), 3)
    elif chain == "corner":
        e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
        fid = np.tile(np.arange(m), 3)
    else:
        raise ValueError(f"chain must be 'face' or 'corner', not {chain!r}")
    e = np.sort(e, 1).astype(np.int64)
    key = e[:, 0] * (int(faces.max()) + 1) + e[:, 1]
    order = np.argsort(key, kind="stable")
    key, fid = key[order], fid[order]
    same = np.nonzero(key[1:] == key[:-1])[0]
    a, b = fid[same], fid[same + 1]
    keep = a != b
    pairs = np.sort(np.stack([a[keep], b[keep]], 1), 1)
    return np.unique(pairs, axis=0) if len(pairs) else np.zeros((0, 2), np.int64)


# --- vertex-set (or face-set) overlaps ------------------------------------------------------------

def _unique_sets(sets: Sequence[np.ndarray]) -> list[np.ndarray]:
    return [np.unique(np.asarray(s, np.int64).ravel()) for s in sets]


def _incidence(sets: list[np.ndarray], inv: np.ndarray, n_cols: int) -> sparse.csr_matrix:
    rows = np.repeat(np.arange(len(sets)), [len(s) for s in sets])
    return sparse.csr_matrix((np.ones(len(rows)), (rows, inv)), shape=(len(sets), n_cols))


def overlap_counts(a_sets: Sequence[np.ndarray], b_sets: Sequence[np.ndarray] | None = None,
                   weights: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``inter[i, j] = |A_i & B_j|`` (dense float, exact counts) and the set sizes ``|A_i|``, ``|B_j|``;
    with ``weights`` (one per id, e.g. face areas) each id counts its weight instead of 1.

    Ids are deduplicated; ``b_sets=None`` compares ``a_sets`` with themselves. One sparse incidence
    product over the ids that occur (no Python loop over pairs)."""
    a = _unique_sets(a_sets)
    b = a if b_sets is None else _unique_sets(b_sets)
    w = None if weights is None else np.asarray(weights, float)
    size_a = np.array([len(s) if w is None else w[s].sum() for s in a], float)
    size_b = size_a if b_sets is None else np.array([len(s) if w is None else w[s].sum() for s in b], float)
    if not a or not b:
        return np.zeros((len(a), len(b))), size_a, size_b
    both = a if b_sets is None else a + b
    ids, inv = np.unique(np.concatenate(both), return_inverse=True)
    inv = inv.ravel()
    n_a = sum(len(s) for s in a)
    A = _incidence(a, inv[:n_a], len(ids))
    B = A if b_sets is None else _incidence(b, inv[n_a:], len(ids))
    if w is not None:  # weighted on one side only: the product sums each shared id's weight once
        A = A.multiply(w[ids][None, :]).tocsr()
    return (A @ B.T).toarray(), size_a, size_b


def iou_from_counts(inter: np.ndarray, size_a: np.ndarray, size_b: np.ndarray) -> np.ndarray:
    """IoU from :func:`overlap_counts`; 0 where both sets are empty."""
    union = size_a[:, None] + size_b[None, :] - inter
    return np.divide(inter, union, out=np.zeros_like(inter, dtype=float), where=union > 0)


def iou_matrix(a_sets: Sequence[np.ndarray], b_sets: Sequence[np.ndarray] | None = None,
               weights: np.ndarray | None = None) -> np.ndarray:
    """(len(a), len(b)) IoU of id sets (vertex ids, face ids); ids deduplicated, empty-vs-empty 0;
    ``weights`` per id (face areas: area IoU)."""
    return iou_from_counts(*overlap_counts(a_sets, b_sets, weights))


def vertex_iou(a: np.ndarray, b: np.ndarray, assume_unique: bool = False) -> float:
    """IoU of two id sets (0 when both are empty)."""
    if not assume_unique:
        a, b = np.unique(np.asarray(a, np.int64)), np.unique(np.asarray(b, np.int64))
    inter = len(np.intersect1d(a, b, assume_unique=True))
    union = len(a) + len(b) - inter
    return inter / union if union else 0.0
