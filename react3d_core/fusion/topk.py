"""Top-k views per proposal: IoU of each 2D mask with the proposal's occlusion-aware silhouette.

The silhouette is the set of pixels of the frame's face-id buffer whose face belongs to the
proposal, so an occluder in front of the part removes its pixels (a plain projection would not).
All proposals of a frame are scored at once with one sparse product.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy import sparse

from ..camera import scaled_area_px, scaled_px
from ..config import PipelineConfig
from ..data.masks import Mask2D
from ..data.parts import TopView
from ..raster.rasterizer import RasterResult
from .lift import ViewStats, lift_with_stats


def big_enough(mask: Mask2D, config: PipelineConfig) -> bool:
    """At least ``min_mask_px`` pixels (an area at 960 px width)."""
    m = mask.mask
    return bool(m.any()) and m.sum() >= scaled_area_px(config.topk.min_mask_px, m.shape[1])


def touches_border(mask: Mask2D, config: PipelineConfig) -> bool:
    """Mask within ``border_px`` (at 960 px width) of the image border: the part is likely cut off."""
    m = mask.mask
    b = scaled_px(config.topk.border_px, m.shape[1])
    return b > 0 and bool(m[:b].any() or m[-b:].any() or m[:, :b].any() or m[:, -b:].any())


def membership_matrix(proposal_faces: Sequence[np.ndarray], n_faces: int) -> sparse.csr_matrix:
    """(n_faces + 1, n_props) binary; the last row is 'no face' (-1 in a buffer)."""
    rows = np.concatenate(proposal_faces) if proposal_faces else np.zeros(0, np.int64)
    cols = np.repeat(np.arange(len(proposal_faces)), [len(p) for p in proposal_faces])
    m = sparse.csr_matrix((np.ones(len(rows), np.float32), (rows, cols)), shape=(n_faces + 1, len(proposal_faces)))
    m.data[:] = 1.0
    return m


def frame_ious(face_ids: np.ndarray, masks: Sequence[np.ndarray], P: sparse.csr_matrix) -> np.ndarray:
    """(n_masks, n_props) IoU of each mask (at the buffer's size) with each proposal's silhouette."""
    ids = face_ids.ravel()
    S = P[np.where(ids >= 0, ids, P.shape[0] - 1)]  # pixels x props
    sil = np.asarray(S.sum(0)).ravel()
    if not len(masks):
        return np.zeros((0, P.shape[1]))
    Mm = sparse.csr_matrix(np.stack([m.ravel() for m in masks]).astype(np.float32))
    inter = (Mm @ S).toarray()
    area = np.asarray(Mm.sum(1)).ravel()
    union = area[:, None] + sil[None, :] - inter
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(union > 0, inter / union, 0.0)


def top_views_from_stats(
    proposal_faces: Sequence[np.ndarray],
    stats: Sequence[ViewStats],
    masks: Mapping[str, Sequence[Mask2D]],
    n_faces: int,
    config: PipelineConfig,
    face_area: np.ndarray | None = None,
) -> list[list[TopView]]:
    """For each proposal, its k best views (one mask per frame) with IoU > ``min_iou``, best first.

    IoUs of all masks with all proposals come from two sparse products of face histograms:
    intersection = mask histogram . proposal membership, silhouette = frame histogram . membership.
    Masks touching the border are skipped; only for a proposal no other mask matches (a part the capture
    always cuts off, e.g. low cabinets) are they used, so such parts are not lost. An inner mask whose
    view sees less than ``min_view_cover`` of what the best-seeing matching view sees of the proposal
    (its surface, ``face_area``; face counts without) is no better than a border mask: the
    occlusion-aware IoU is high in a view that sees a corner of a tall door past an obstacle, and
    re-segmenting there returns that corner only.
    """
    n_p = len(proposal_faces)
    out: list[list[TopView]] = [[] for _ in range(n_p)]
    rows = [(si, j) for si, st in enumerate(stats) for j in range(len(st.mask_index))]
    if not n_p or not rows:
        return out
    P = membership_matrix(proposal_faces, n_faces)[:n_faces]

    def hist(face_lists: list[np.ndarray], count_lists: list[np.ndarray]) -> sparse.csr_matrix:
        r = np.repeat(np.arange(len(face_lists)), [len(f) for f in face_lists])
        return sparse.csr_matrix((np.concatenate(count_lists).astype(np.float64), (r, np.concatenate(face_lists))),
                                 shape=(len(face_lists), n_faces))

    Hf = hist([st.faces for st in stats], [st.counts for st in stats])
    Hm = hist([stats[si].mask_faces[j] for si, j in rows], [stats[si].mask_counts[j] for si, j in rows])
    sil = (Hf @ P).toarray()  # frames x props
    inter = (Hm @ P).toarray()  # masks x props
    frame_of = np.array([si for si, _ in rows])
    area = np.array([stats[si].mask_area[j] for si, j in rows], float)
    border = np.array([stats[si].at_border[j] for si, j in rows])
    union = area[:, None] + sil[frame_of] - inter
    with np.errstate(divide="ignore", invalid="ignore"):
        iou = np.where(union > 0, inter / union, 0.0)
    match = iou > config.topk.min_iou
    inner = np.repeat(~border[:, None], n_p, 1)
    if config.topk.min_view_cover > 0:
        w = np.ones(n_faces) if face_area is None else np.asarray(face_area, float)[:n_faces]
        seen = (_seen_area(Hf, w) @ P).toarray()[frame_of]  # masks x props: proposal surface the mask's view sees
        best_seen = np.where(match, seen, 0.0).max(0)
        inner &= seen >= config.topk.min_view_cover * best_seen
    for p in range(n_p):
        col = iou[:, p]
        for sel in (inner[:, p], np.ones(len(col), bool)):  # inner masks first; all matching masks as a fallback
            cand = np.nonzero(sel & match[:, p])[0]
            if not len(cand):
                continue
            best: dict[int, int] = {}
            for r in cand[np.argsort(-col[cand], kind="stable")]:
                best.setdefault(int(frame_of[r]), int(r))  # one mask per frame, its best
            chosen = sorted(best.values(), key=lambda r: (-col[r], stats[frame_of[r]].frame_id))[: config.topk.k]
            for r in chosen:
                st = stats[frame_of[r]]
                mk = masks[st.frame_id][st.mask_index[rows[r][1]]]
                out[p].append(TopView(frame_id=st.frame_id, iou=float(col[r]), mask=mk))
            break
    return out


def _seen_area(H: sparse.csr_matrix, face_area: np.ndarray) -> sparse.csr_matrix:
    """Frame x face histogram -> the area of each face the frame sees (pixel counts replaced by area)."""
    out = H.tocsr(copy=True)
    out.data = face_area[out.indices]
    return out


def select_top_views(
    proposal_faces: Sequence[np.ndarray],
    buffers: dict[str, np.ndarray],
    masks: Mapping[str, Sequence[Mask2D]],
    n_faces: int,
    config: PipelineConfig,
) -> list[list[TopView]]:
    """Top-k views from face-id buffers and masks (see :func:`top_views_from_stats`)."""
    stats = []
    for fid, ids in buffers.items():
        ms = list(masks.get(fid, []))
        if ms:
            stats.append(lift_with_stats(RasterResult(fid, ids, np.zeros(ids.shape, np.float32)), ms, config)[1])
    return top_views_from_stats(proposal_faces, stats, masks, n_faces, config)
