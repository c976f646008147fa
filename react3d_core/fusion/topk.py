"""Top-k views per proposal: IoU of each 2D mask with the proposal's occlusion-aware silhouette.

The silhouette is the set of pixels of the frame's face-id buffer whose face belongs to the
proposal, so an occluder in front of the part removes its pixels (a plain projection would not).
All proposals of a frame are scored at once with one sparse product.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy import sparse

from ..config import PipelineConfig
from ..data.masks import Mask2D
from ..data.parts import TopView
from .lift import REF_WIDTH, filled, scaled_px


def big_enough(mask: Mask2D, config: PipelineConfig) -> bool:
    """At least ``min_mask_px`` pixels (an area at 960 px width)."""
    m = mask.mask
    return bool(m.any()) and m.sum() >= config.topk.min_mask_px * (m.shape[1] / REF_WIDTH) ** 2


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


def select_top_views(
    proposal_faces: Sequence[np.ndarray],
    buffers: dict[str, np.ndarray],
    masks: Mapping[str, Sequence[Mask2D]],
    n_faces: int,
    config: PipelineConfig,
) -> list[list[TopView]]:
    """For each proposal, its k best views (one mask per frame) with IoU > ``min_iou``, best first.

    Masks touching the border are skipped; only for a proposal no other mask matches (a part the
    capture always cuts off, e.g. low cabinets) are they used, so such parts are not lost.
    """
    P = membership_matrix(proposal_faces, n_faces)
    inner: list[list[TopView]] = [[] for _ in proposal_faces]
    border: list[list[TopView]] = [[] for _ in proposal_faces]
    for fid, ids in buffers.items():
        ms = [m for m in masks.get(fid, []) if big_enough(m, config)]
        if not ms or not len(proposal_faces):
            continue
        prepared = [filled(m.mask, ids.shape, config) for m in ms]
        at_border = np.array([touches_border(m, config) for m in ms])
        iou = frame_ious(ids, prepared, P)
        for group, sel in ((inner, ~at_border), (border, at_border)):
            if not sel.any():
                continue
            sub = np.where(sel[:, None], iou, -1.0)
            j = np.argmax(sub, 0)
            top = sub[j, np.arange(sub.shape[1])]
            for p in np.nonzero(top > config.topk.min_iou)[0]:
                group[p].append(TopView(frame_id=fid, iou=float(top[p]), mask=ms[int(j[p])]))
    out = []
    for a, b in zip(inner, border):
        views = a if a else b
        out.append(sorted(views, key=lambda t: (-t.iou, t.frame_id))[: config.topk.k])
    return out
