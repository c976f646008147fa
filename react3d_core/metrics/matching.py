"""Vertex-level IoU between predicted and ground-truth movable parts (sparse, vectorised)."""

from __future__ import annotations

import numpy as np
from scipy import sparse


def _indicator(sets: list[np.ndarray], n_vertices: int) -> sparse.csr_matrix:
    rows = np.concatenate([np.full(len(s), i, np.int64) for i, s in enumerate(sets)]) if sets else np.zeros(0, np.int64)
    cols = np.concatenate(sets).astype(np.int64) if sets else np.zeros(0, np.int64)
    m = sparse.csr_matrix((np.ones(len(rows), np.float64), (rows, cols)), shape=(len(sets), n_vertices))
    m.data[:] = 1.0  # duplicates summed by csr: back to a 0/1 indicator
    return m


def iou_matrix(pred_sets: list[np.ndarray], gt_sets: list[np.ndarray]) -> np.ndarray:
    """(n_pred, n_gt) IoU of vertex-id sets; ids are deduplicated, empty-vs-empty gives 0."""
    pred_sets = [np.unique(np.asarray(s, np.int64)) for s in pred_sets]
    gt_sets = [np.unique(np.asarray(s, np.int64)) for s in gt_sets]
    if not pred_sets or not gt_sets:
        return np.zeros((len(pred_sets), len(gt_sets)))
    n = int(max([s.max() + 1 for s in pred_sets + gt_sets if len(s)] or [1]))
    P, G = _indicator(pred_sets, n), _indicator(gt_sets, n)
    inter = np.asarray((P @ G.T).todense(), float)
    sp = np.array([len(s) for s in pred_sets], float)
    sg = np.array([len(s) for s in gt_sets], float)
    union = sp[:, None] + sg[None, :] - inter
    return np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
