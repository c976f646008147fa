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
Stage 5 (ours): a piece — a part that moves as a larger kept part does (same joint type, axes and front
normals within ``motion_angle_deg``, hinge lines within ``motion_hinge_m``) with >= ``motion_share`` of
its front's footprint inside that part's front — is merged into it (vertices, faces, box). Fusion
sometimes splits a strip off a front (its bottom, seen from one view) that reaches past the larger part's
box, so stages 3 and 4 keep it; the same motion says it is the same door or drawer, while a door
stacked on the same hinge line or a neighbouring drawer shares no footprint. Left in, it is a second
body in the same place: it jams the part and blocks its front.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from ..config import DedupConfig
from ..data.parts import OBB, Articulation
from ..geometry import iou_from_counts, overlap_counts, vertex_iou

T = TypeVar("T")


def _face_grid(box: OBB, n: int = 9) -> np.ndarray:
    """``n`` x ``n`` points evenly over the box's mid-plane (axes 1 and 2: the front's footprint)."""
    t = (np.arange(n) + 0.5) / n - 0.5
    a, b = np.meshgrid(t * box.extents[0], t * box.extents[1], indexing="ij")
    R = box.R
    return np.asarray(box.center) + a.reshape(-1, 1) * R[:, 0] + b.reshape(-1, 1) * R[:, 1]


def footprint_share(small: OBB, large: OBB, margin: float, slab: float) -> float:
    """Share of ``small``'s front footprint inside ``large``'s (grown in its plane by ``margin``), counted
    where it lies within ``slab`` of ``large``'s slab along its normal. Sampled on a grid, so it is an
    area share, independent of how densely the scan meshed either part."""
    local = (_face_grid(small) - np.asarray(large.center)) @ large.R
    half = np.asarray(large.extents) / 2
    inside = (np.abs(local[:, :2]) <= half[:2] + margin).all(1) & (np.abs(local[:, 2]) <= half[2] + slab)
    return float(inside.mean())


def same_motion(a: Articulation, b: Articulation, normal_a: np.ndarray, normal_b: np.ndarray,
                cfg: DedupConfig) -> bool:
    """Whether two parts move alike: same joint type, axes and front normals within ``motion_angle_deg``
    (signs count: a door hinged the other way opens the other way), hinge lines within ``motion_hinge_m``."""
    cos = np.cos(np.radians(cfg.motion_angle_deg))
    ax_a, ax_b = np.asarray(a.axis, float), np.asarray(b.axis, float)
    if a.joint_type != b.joint_type or ax_a @ ax_b < cos or np.asarray(normal_a) @ np.asarray(normal_b) < cos:
        return False
    if a.joint_type != "revolute":
        return True
    d = np.asarray(a.origin, float) - np.asarray(b.origin, float)
    return bool(np.linalg.norm(d - (d @ ax_b) * ax_b) <= cfg.motion_hinge_m)


def dedup_indices(sets: Sequence[np.ndarray], cfg: DedupConfig, points: Sequence[np.ndarray] | None = None,
                  boxes: Sequence[OBB] | None = None,
                  motions: Sequence[tuple[Articulation, np.ndarray, bool]] | None = None) -> list[int]:
    """Indices (into ``sets``) of the parts kept, in their original order (see ``dedup_plan``)."""
    return dedup_plan(sets, cfg, points, boxes, motions)[0]


def dedup_plan(sets: Sequence[np.ndarray], cfg: DedupConfig, points: Sequence[np.ndarray] | None = None,
               boxes: Sequence[OBB] | None = None,
               motions: Sequence[tuple[Articulation, np.ndarray, bool]] | None = None,
               ) -> tuple[list[int], dict[int, list[int]]]:
    """Indices (into ``sets``) of the parts kept, in their original order, and the pieces each kept part
    absorbs (stage 5). Stage 4 needs each part's ``points`` and ``boxes``, stage 5 ``boxes`` and
    ``motions`` (articulation, front normal, sliding); without them they are skipped."""
    n = len(sets)
    if n == 0:
        return [], {}
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
    merged: dict[int, list[int]] = {}
    if boxes is not None and motions is not None:
        for i in order[::-1]:  # stage 5, smaller first, into the larger kept part it overlaps most
            if not alive[i]:
                continue
            art_i, n_i, slide_i = motions[i]
            best, into = cfg.motion_share, -1
            for j in np.flatnonzero(alive & (size > size[i])):
                art_j, n_j, slide_j = motions[j]
                if slide_i != slide_j or not same_motion(art_i, art_j, n_i, n_j, cfg):
                    continue
                share = footprint_share(boxes[i], boxes[j], cfg.footprint_margin_m, cfg.motion_slab_m)
                if share >= best:
                    best, into = share, int(j)
            if into >= 0:
                alive[i] = False
                merged.setdefault(into, []).append(int(i))
    kept = [int(i) for i in np.flatnonzero(alive)]
    return kept, {j: sorted(merged[j]) for j in kept if j in merged}


def grown_box(box: OBB, others: Sequence[OBB]) -> OBB:
    """``box`` grown in its front plane (axes 1 and 2) to cover the footprints of ``others``; its
    thickness and normal stay (a piece of a front lies in the same slab)."""
    R = box.R
    local = np.vstack([(o.corners() - np.asarray(box.center)) @ R for o in others] + [np.zeros((1, 3))])
    half = np.asarray(box.extents, float) / 2
    lo = np.minimum(local.min(0), -half)
    hi = np.maximum(local.max(0), half)
    lo[2], hi[2] = -half[2], half[2]
    center = np.asarray(box.center) + R @ ((lo + hi) / 2)
    ext = hi - lo
    axes = np.asarray(box.axes, float)
    if ext[1] > ext[0]:  # keep extents in decreasing order: (u, v, n) -> (v, -u, n), still right-handed
        axes, ext = np.array([axes[1], -axes[0], axes[2]]), ext[[1, 0, 2]]
    return OBB(center=tuple(center), axes=tuple(map(tuple, axes)), extents=tuple(ext))


def remove_duplicates(parts: Sequence[T], cfg: DedupConfig, vertices: np.ndarray | None = None) -> list[T]:
    """Parts (anything with ``vertex_ids``; with ``obb`` too for stage 4) without duplicates;
    ``vertices`` (the scan's) enable stage 4. Parts that are dataclasses with ``articulation``,
    ``front_normal``, ``sliding`` and ``face_ids`` (articulated parts) also go through stage 5: a kept
    part takes its pieces' vertices and faces, and its box grows over their footprints."""
    sets = [p.vertex_ids for p in parts]  # type: ignore[attr-defined]
    if vertices is None or not all(getattr(p, "obb", None) is not None for p in parts):
        return [parts[i] for i in dedup_indices(sets, cfg)]
    pts = [vertices[np.asarray(v, np.int64)] for v in sets]
    boxes = [p.obb for p in parts]  # type: ignore[attr-defined]
    movable = all(dataclasses.is_dataclass(p) and all(hasattr(p, a) for a in
                  ("articulation", "front_normal", "sliding", "face_ids")) for p in parts)
    motions = [(p.articulation, np.asarray(p.front_normal, float), bool(p.sliding))  # type: ignore[attr-defined]
               for p in parts] if movable else None
    kept, merged = dedup_plan(sets, cfg, pts, boxes, motions)
    out = []
    for i in kept:
        p = parts[i]
        if i in merged:
            pieces = [parts[k] for k in merged[i]]
            p = dataclasses.replace(  # type: ignore[type-var]
                p, vertex_ids=np.unique(np.concatenate([np.asarray(q.vertex_ids, np.int64) for q in (p, *pieces)])),
                face_ids=np.unique(np.concatenate([np.asarray(q.face_ids, np.int64) for q in (p, *pieces)])),
                obb=grown_box(p.obb, [q.obb for q in pieces]))
        out.append(p)
    return out
