"""Duplicate removal (paper Sec. "Interactive scene integration"), with a bounded stage 2.

Stage 1: parts whose vertex sets overlap with IoU >= tau_dup -> keep the larger.
Stage 2: a part covered by a union of smaller parts (each with IoU >= tau_low against it) with
IoU >= cover_iou is removed (it merged several fronts). The reference enumerated every subset of the
smaller parts (2^n); here a greedy cover over at most ``max_candidates`` parts, largest overlap first,
is O(n * k). Overlaps come from one sparse incidence product (``geometry.overlap_counts``), not Python pairs.
Stage 3 (ours): a fragment — a part with >= tau_contained of its vertices inside one larger kept part —
is removed. Distinct physical parts share at most boundary vertices, so such a part is a piece of the
larger one (a frame or a panel of a frame-and-panel door that fusion also proposed on its own).
Stage 3 also removes a bridge: a part with ``bridge_share`` of its vertices inside other kept parts, split
over at least two of them — a mask that spans the seam between two fronts whose own masks are kept (the
halves of a double door). Its box spans both fronts, so each front's probe meets it.
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
body in the same place: it jams the part and blocks its front. A scrap — a part whose front's shorter side
is under ``scrap_max_m``, smaller than any front — is merged into the larger kept part whose footprint
(grown by ``scrap_reach_m``) holds ``tau_contained`` of its points, whatever its motion: the box of a few
centimetres of surface gives no reliable normal (a corner the larger part's masks missed came out 14° off).
Stage 6 (ours): an enclosing part — a mask merged around a smaller kept part in the same plane (a drawer's
mask that took the drawers around a door, leaving the door's front a hole in it) — is cut back off it
(``cut_enclosing``): its box spanned the other part's front, so each front's probe met the other's
colliders and the hinge, cavity and carcass reached over its neighbour. A part cut back goes through
stages 1-5 again: what is left of it can lie over a front whose own mask is kept (a duplicate).
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
    # a scrap (smaller than any front) shares its few vertices with every neighbour: no bridge, stage 5 merges it
    scrap = np.array([b.extents[0] < cfg.scrap_max_m or b.extents[1] < cfg.scrap_max_m for b in boxes]
                     if boxes is not None else np.zeros(n, bool), bool)
    for i in order:  # stage 3, bridges: larger first, so a bridge goes before the fronts it spans are judged
        if not alive[i] or scrap[i]:
            continue
        holders = np.flatnonzero(alive & (contained[i] >= cfg.tau_low))
        holders = holders[holders != i]
        if len(holders) < 2:
            continue
        union = np.unique(np.concatenate([sets_u[j] for j in holders]))
        if np.isin(sets_u[i], union, assume_unique=True).mean() >= cfg.bridge_share:
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
            if scrap[i] and points is not None and len(points[i]):
                # into the part that reaches most of it, shares most of its vertices (its surface), is nearest
                fits = [(float(_footprint_mask(points[i], boxes[j], cfg.motion_slab_m, cfg.scrap_reach_m).mean()),
                         float(inter[i, j]), -_outside_m(points[i], boxes[j]), int(j))
                        for j in np.flatnonzero(alive & (size > size[i]))]
                fits = [t for t in fits if t[0] >= cfg.tau_contained]
                into = max(fits)[-1] if fits else -1
            else:
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


def _outside_m(points: np.ndarray, box: OBB) -> float:
    """Mean distance (m) in ``box``'s front plane from ``points`` to its footprint (0 inside)."""
    local = (np.asarray(points, float) - np.asarray(box.center)) @ box.R
    return float(np.linalg.norm(np.maximum(np.abs(local[:, :2]) - np.asarray(box.extents[:2]) / 2, 0.0), axis=1).mean())


def _footprint_mask(points: np.ndarray, box: OBB, slab: float, margin: float = 0.0) -> np.ndarray:
    """Points inside ``box``'s front footprint (grown in its plane by ``margin``), within ``slab`` of its
    slab along its normal."""
    local = (np.asarray(points, float) - np.asarray(box.center)) @ box.R
    half = np.asarray(box.extents) / 2
    return (np.abs(local[:, :2]) <= half[:2] + margin).all(1) & (np.abs(local[:, 2]) <= half[2] + slab)


@dataclasses.dataclass
class EnclosedCut:
    """How a merged part is cut back off the part it encloses: the faces it keeps and its new box."""

    face_ids: np.ndarray
    vertex_ids: np.ndarray
    obb: OBB


def enclosing_cut(big: OBB, big_faces: np.ndarray, small: OBB, vertices: np.ndarray, faces: np.ndarray,
                  cfg: DedupConfig, samples: int = 4000) -> EnclosedCut | None:
    """The cut of ``big`` (its scan faces ``big_faces``) back off ``small``'s footprint, or None when
    ``big`` is no mask merged around it.

    Merged around it: ``small``'s footprint lies in ``big``'s box (``enclosed_share``, in its slab) while
    ``big``'s own surface covers that footprint at most ``enclosed_fill_max`` as densely as its box on
    average (by area, whatever the tessellation): a hole in it. A smaller part over surface ``big`` does
    cover is a piece of it or a duplicate (the earlier stages), or a dispute geometry alone cannot settle
    (two masks over one front): left. The box then spans a front that is not its own: the hinge, the
    cavity and the colliders reach over the other part. Of the four cuts along ``big``'s front sides at
    the edges of ``small``'s footprint (``footprint_margin_m`` off), the one keeping most of that surface
    is made: faces whose centroid lies past it go, and the box shrinks to what is kept (its normal and
    thickness stay)."""
    from ..articulation.obb import surface_samples

    if footprint_share(small, big, cfg.footprint_margin_m, cfg.motion_slab_m) < cfg.enclosed_share:
        return None
    # of big's footprint, the share small's covers: small's area times the share of it inside big's box
    area_share = float(np.prod(small.extents[:2]) * footprint_share(small, big, 0.0, np.inf) / max(np.prod(big.extents[:2]), 1e-12))
    if area_share <= 0 or area_share >= 0.5:
        return None  # small is no smaller in the plane: a duplicate, the earlier stages' business
    own = np.asarray(big_faces, np.int64)
    pts = surface_samples(vertices[faces[own]], samples, np.random.default_rng(0)) if len(own) else np.zeros((0, 3))
    if len(pts) < 100:
        return None
    fill = float(_footprint_mask(pts, small, cfg.motion_slab_m).mean()) / area_share
    if fill > cfg.enclosed_fill_max:
        return None
    R, c = big.R, np.asarray(big.center)
    local = (pts - c) @ R
    s_local = (small.corners() - c) @ R
    lo_s, hi_s = s_local.min(0) - cfg.footprint_margin_m, s_local.max(0) + cfg.footprint_margin_m
    options = [(int((local[:, k] <= lo_s[k]).sum()), k, -1) for k in (0, 1)] + [(int((local[:, k] >= hi_s[k]).sum()), k, 1) for k in (0, 1)]
    kept_n, k, side = max(options)
    if kept_n == 0:
        return None
    cen = (vertices[faces[own]].mean(1) - c) @ R
    keep = own[(cen[:, k] <= lo_s[k]) if side < 0 else (cen[:, k] >= hi_s[k])]
    if not len(keep):
        return None
    vids = np.unique(faces[keep].ravel())
    vl = (vertices[vids] - c) @ R
    half = np.asarray(big.extents, float) / 2
    lo, hi = vl.min(0), vl.max(0)
    lo[2], hi[2] = -half[2], half[2]
    ext, axes = hi - lo, np.asarray(big.axes, float)
    if ext[1] > ext[0]:  # extents in decreasing order: (u, v, n) -> (v, -u, n), still right-handed
        axes, ext = np.array([axes[1], -axes[0], axes[2]]), ext[[1, 0, 2]]
    box = OBB(center=tuple(c + R @ ((lo + hi) / 2)), axes=tuple(map(tuple, axes)), extents=tuple(ext))
    return EnclosedCut(keep, vids, box)


def cut_enclosing(parts: list[T], cfg: DedupConfig, vertices: np.ndarray, faces: np.ndarray) -> list[T]:
    """Stage 6: each part merged around a smaller kept part in its plane (``enclosing_cut``) cut back off
    it, larger parts first; a flat door's hinge is refined again on the new box (the paper's rule: the
    edge nearer the predicted axis)."""
    from ..articulation.refine import refine_revolute, slab_mid_and_thickness

    out = list(parts)
    area = [float(np.prod(p.obb.extents[:2])) for p in out]  # type: ignore[attr-defined]
    cos = np.cos(np.radians(cfg.motion_angle_deg))
    for i in sorted(range(len(out)), key=lambda i: -area[i]):
        for j in range(len(out)):
            big, small = out[i], out[j]
            if j == i or area[j] >= area[i]:
                continue
            if float(np.asarray(big.front_normal) @ np.asarray(small.front_normal)) < cos:  # type: ignore[attr-defined]
                continue
            cut = enclosing_cut(big.obb, big.face_ids, small.obb, vertices, faces, cfg)  # type: ignore[attr-defined]
            if cut is None:
                continue
            art = big.articulation  # type: ignore[attr-defined]
            if art.joint_type == "revolute" and big.flat and not big.sliding:  # type: ignore[attr-defined]
                mid, _ = slab_mid_and_thickness(vertices[cut.vertex_ids], np.asarray(cut.obb.center),
                                                np.asarray(big.front_normal, float))  # type: ignore[attr-defined]
                art = refine_revolute(big.initial, cut.obb, mid).model_copy(  # type: ignore[attr-defined]
                    update={"lower": art.lower, "upper": art.upper, "limit_source": art.limit_source})
            out[i] = dataclasses.replace(big, face_ids=cut.face_ids, vertex_ids=cut.vertex_ids, obb=cut.obb,  # type: ignore[type-var]
                                         articulation=art)
            area[i] = float(np.prod(cut.obb.extents[:2]))
    return out


def remove_duplicates(parts: Sequence[T], cfg: DedupConfig, vertices: np.ndarray | None = None,
                      faces: np.ndarray | None = None) -> list[T]:
    """Parts (anything with ``vertex_ids``; with ``obb`` too for stage 4) without duplicates;
    ``vertices`` (the scan's) enable stage 4. Parts that are dataclasses with ``articulation``,
    ``front_normal``, ``sliding`` and ``face_ids`` (articulated parts) also go through stage 5: a kept
    part takes its pieces' vertices and faces, and its box grows over their footprints; with the scan's
    ``faces`` also through stage 6 (``cut_enclosing``)."""
    sets = [p.vertex_ids for p in parts]  # type: ignore[attr-defined]
    if vertices is None or not all(getattr(p, "obb", None) is not None for p in parts):
        return [parts[i] for i in dedup_indices(sets, cfg)]
    out = _merge_pass(parts, cfg, vertices)
    if faces is None or not all(hasattr(p, a) for p in out for a in ("initial", "flat")):
        return out
    faces = np.asarray(faces, np.int64)
    for _ in range(3):
        cut = cut_enclosing(out, cfg, vertices, faces)
        if all(c is o for c, o in zip(cut, out)):
            break
        # a mask that took a front and the fronts beside it, cut back off those, can be left over the
        # front it took, where that front's own mask is kept too: the cut parts go through stages 1-5 again
        out = _merge_pass(cut, cfg, vertices)
    return out


def _merge_pass(parts: Sequence[T], cfg: DedupConfig, vertices: np.ndarray) -> list[T]:
    """Stages 1-5 over ``parts`` (with boxes), pieces merged into the parts that keep them."""
    sets = [p.vertex_ids for p in parts]  # type: ignore[attr-defined]
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
