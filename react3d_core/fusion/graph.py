"""Face co-occurrence graph (scipy.sparse) and Louvain communities over several resolutions.

Two kinds of face pairs are counted, both linear in the lifted faces:
* mesh-adjacent pairs (faces sharing an edge): exact counts of masks containing both, from one
  sparse product — this is what separates two coplanar doors sharing an edge;
* anchor pairs: every face of a mask is paired with the mask's ``a`` highest-priority faces
  (one global seeded priority, so the same pairs recur across masks and their counts add up),
  ``a <= max_anchors`` (8), ``a * |mask| <= max_pairs_per_mask`` (a mask larger than that pairs its first max_pairs faces in a
  second global priority with one anchor). They tie together faces that are not adjacent (a door split
  by an occluder or a handle hole).
Louvain runs on the graph contracted by mask signature (faces lying in exactly the same masks
are indistinguishable to the graph; contracting them is Louvain's own first aggregation step).
"""

from __future__ import annotations

from collections.abc import Sequence

import networkx as nx
import numpy as np
from scipy import sparse


def membership(face_sets: Sequence[np.ndarray], n_nodes: int) -> sparse.csr_matrix:
    """(n_masks, n_nodes) binary matrix of which nodes each mask covers."""
    if not face_sets:
        return sparse.csr_matrix((0, n_nodes), dtype=np.float32)
    rows = np.repeat(np.arange(len(face_sets)), [len(s) for s in face_sets])
    cols = np.concatenate(face_sets)
    m = sparse.csr_matrix((np.ones(len(cols), np.float32), (rows, cols)), shape=(len(face_sets), n_nodes))
    m.data[:] = 1.0
    return m


def anchor_pairs(face_sets: Sequence[np.ndarray], n_nodes: int, max_pairs: int, seed: int, max_anchors: int = 8) -> np.ndarray:
    """(P,2) sampled pairs (i < j), at most ``max_pairs`` per mask, each face paired with at most
    ``max_anchors`` anchors of its mask (config.fusion.max_anchors); duplicates across masks kept."""
    rng = np.random.default_rng(seed)
    prio = rng.permutation(n_nodes)
    prio2 = rng.permutation(n_nodes)  # picks the faces paired in masks larger than max_pairs
    out = []
    for s in face_sets:
        n = len(s)
        if n < 2:
            continue
        if n > max_pairs:
            s = s[np.argpartition(prio2[s], max_pairs - 1)[:max_pairs]]
            n = max_pairs
        a = int(min(n - 1, max_anchors, max(1, max_pairs // n)))
        anchors = s[np.argpartition(prio[s], a - 1)[:a]] if a < n else s
        i = np.repeat(s, len(anchors))
        j = np.tile(anchors, n)
        keep = i != j
        key = np.unique(np.minimum(i, j)[keep].astype(np.int64) * n_nodes + np.maximum(i, j)[keep])  # once per mask
        out.append(np.stack([key // n_nodes, key % n_nodes], 1))
    return np.concatenate(out) if out else np.zeros((0, 2), np.int64)


def cooccurrence(face_sets: Sequence[np.ndarray], n_nodes: int, adjacency: np.ndarray, max_pairs: int, seed: int,
                 max_anchors: int = 8) -> sparse.coo_matrix:
    """Upper-triangular counts: how many masks contain both faces of each counted pair."""
    M = membership(face_sets, n_nodes).tocsc()
    cnt = []
    if len(adjacency) and M.shape[0]:
        used = np.asarray(M.sum(0)).ravel() > 0
        adj = adjacency[used[adjacency[:, 0]] & used[adjacency[:, 1]]]
        if len(adj):
            c = np.asarray(M[:, adj[:, 0]].multiply(M[:, adj[:, 1]]).sum(0)).ravel()
            cnt.append(sparse.coo_matrix((c, (adj[:, 0], adj[:, 1])), shape=(n_nodes, n_nodes)).tocsr())
    ap = anchor_pairs(face_sets, n_nodes, max_pairs, seed, max_anchors)
    if len(ap):
        a = sparse.coo_matrix((np.ones(len(ap), np.float32), (ap[:, 0], ap[:, 1])), shape=(n_nodes, n_nodes)).tocsr()
        a.sum_duplicates()
        cnt.append(a)
    if not cnt:
        return sparse.coo_matrix((n_nodes, n_nodes), dtype=np.float32)
    out = cnt[0]
    for c in cnt[1:]:
        out = out.maximum(c)  # an adjacent anchor pair must not be counted twice
    out = sparse.triu(out, 1).tocoo()
    out.eliminate_zeros()
    return out


def face_graph(counts: sparse.coo_matrix, min_cooccurrence: int) -> sparse.coo_matrix:
    """Weighted face graph: keep pairs co-occurring in >= ``min_cooccurrence`` masks."""
    keep = counts.data >= min_cooccurrence
    return sparse.coo_matrix((counts.data[keep], (counts.row[keep], counts.col[keep])), shape=counts.shape)


def louvain(graph: sparse.coo_matrix, nodes: np.ndarray, signature: np.ndarray, resolutions: Sequence[float], seed: int) -> list[tuple[float, np.ndarray]]:
    """Communities (arrays of node ids) of the graph over ``nodes`` for each resolution.

    Nodes with equal ``signature`` are contracted first (self-loops keep their internal weight).
    """
    _, grp = np.unique(signature, return_inverse=True)
    ng = int(grp.max()) + 1 if len(grp) else 0
    pos = np.full(graph.shape[0], -1, np.int64)
    pos[nodes] = np.arange(len(nodes))
    r, c = pos[graph.row], pos[graph.col]
    ok = (r >= 0) & (c >= 0)
    gr, gc, w = grp[r[ok]], grp[c[ok]], graph.data[ok].astype(float)
    g = sparse.coo_matrix((w, (np.minimum(gr, gc), np.maximum(gr, gc))), shape=(ng, ng)).tocsr()
    g.sum_duplicates()
    g = g.tocoo()
    G = nx.Graph()
    G.add_nodes_from(range(ng))
    G.add_weighted_edges_from(zip(g.row.tolist(), g.col.tolist(), g.data.tolist()))
    order = np.argsort(grp, kind="stable")
    splits = np.cumsum(np.bincount(grp, minlength=ng))[:-1]
    members = np.split(nodes[order], splits)
    out = []
    for res in resolutions:
        for com in nx.community.louvain_communities(G, weight="weight", resolution=res, seed=seed):
            out.append((float(res), np.sort(np.concatenate([members[i] for i in com]))))
    return out
