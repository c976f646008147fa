"""Duplicate removal (paper Sec. "Interactive scene integration"), with a bounded stage 2.

Stage 1: parts whose vertex sets overlap with IoU >= tau_dup -> keep the larger.
Stage 2: a part covered by a union of smaller parts (each with IoU >= tau_low against it) with
IoU >= cover_iou is removed (it merged several fronts). The reference enumerated every subset of the
smaller parts (2^n); here a greedy cover over at most ``max_candidates`` parts, largest overlap first,
is O(n * k). Overlaps come from one sparse incidence product (``geometry.overlap_counts``), not Python pairs.
Stage 3 (ours): a fragment — a part with >= tau_contained of its vertices inside one larger kept part —
is removed. Distinct physical parts share at most boundary vertices, so such a part is a piece of the
larger one (a frame or a panel of a frame-and-panel door that fusion also proposed on its own).
Stage 4 (ours): a sliver — a part with at most ``fragment_share`` of a larger kept part's vertices and
>= tau_contained of its points inside that part's box (grown by ``footprint_margin_m``) — is removed.
Fusion sometimes splits a corner off a front (seen occluded in some views); the corner's vertices are
not the larger part's, so stage 3 misses it, but it lies in the larger part's own slab.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from ..config import DedupConfig
from ..data.parts import OBB
from ..geometry import iou_from_counts, overlap_counts, vertex_iou

T = TypeVar("T")


def dedup_indices(sets: Sequence[np.ndarray], cfg: DedupConfig, points: Sequence[np.ndarray] | None = None,
                  boxes: Sequence[OBB] | None = None) -> list[int]:
    """Indices (into ``sets``) of the parts kept, in their original order. Stage 4 needs each part's
    ``points`` and ``boxes``; without them it is skipped."""
    n = len(sets)
    if n == 0:
        return []
    inter, size, _ = overlap_counts(sets)
    iou = iou_from_counts(inter, size, size)
    order = np.argsort(-size, kind="stable")
    alive = np.ones(n, bool)
    for i in order:  # stage 1, larger first
        if not alive[i]:
            continue
        dup = (iou[i] >= cfg.tau_dup) & alive & (size <= size[i])
        dup[i] = False
        alive[dup] = False
    sets_u = [np.unique(np.asarray(s, np.int64)) for s in sets]
    for i in order:  # stage 2
        if not alive[i]:
            continue
        cand = np.flatnonzero(alive & (size < size[i]) & (iou[i] >= cfg.tau_low))
        if len(cand) < 2:
            continue
        cand = cand[np.argsort(-inter[i, cand], kind="stable")][: cfg.max_candidates]
        cover = np.zeros(0, np.int64)
        best = 0.0
        for j in cand:  # greedy: add a part while it improves the union's IoU with part i
            new = np.union1d(cover, sets_u[j])
            iou_new = vertex_iou(new, sets_u[i], assume_unique=True)
            if iou_new > best:
                cover, best = new, iou_new
        if best >= cfg.cover_iou:
            alive[i] = False
    contained = inter / np.maximum(size[:, None], 1e-12)  # [i, j] = share of part i inside part j
    for i in order[::-1]:  # stage 3, smaller first
        inside = alive & (size > size[i]) & (contained[i] >= cfg.tau_contained)
        if alive[i] and inside.any():
            alive[i] = False
    if points is not None and boxes is not None:
        for i in order[::-1]:  # stage 4, smaller first, against larger kept parts
            if not alive[i] or not len(points[i]):
                continue
            for j in np.flatnonzero(alive & (size * cfg.fragment_share >= size[i])):
                if j != i and boxes[j].contains(points[i], cfg.footprint_margin_m).mean() >= cfg.tau_contained:
                    alive[i] = False
                    break
    return [int(i) for i in np.flatnonzero(alive)]


def remove_duplicates(parts: Sequence[T], cfg: DedupConfig, vertices: np.ndarray | None = None) -> list[T]:
    """Parts (anything with ``vertex_ids``; with ``obb`` too for stage 4) without duplicates;
    ``vertices`` (the scan's) enable stage 4."""
    sets = [p.vertex_ids for p in parts]  # type: ignore[attr-defined]
    if vertices is None or not all(getattr(p, "obb", None) is not None for p in parts):
        return [parts[i] for i in dedup_indices(sets, cfg)]
    pts = [vertices[np.asarray(v, np.int64)] for v in sets]
    return [parts[i] for i in dedup_indices(sets, cfg, pts, [p.obb for p in parts])]  # type: ignore[attr-defined]
