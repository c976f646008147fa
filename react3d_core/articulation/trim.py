"""Trim a candidate that holds a neighbour to the part the articulation predictor sees.

Validation (the paper) needs one top view whose predicted part mask matches the candidate's. A
re-segmentation that grew a drawer into the door below it (SAM answering a click with the whole cabinet)
passes in a view where the door is hidden, and the drawer's joint is then given to the drawer and the
door together: the part matches neither (a false part, with a joint fitted to the wrong box). The views
tell them apart: the faces the validating view shows inside its predicted mask are the part's *core*; in
every other top view the prediction that covers the core's pixels is the same part seen again, and the
candidate's faces that view shows outside that mask belong to something else. Views are taken in turn,
the one showing most of the part known so far first, and what each shows inside its covering prediction
joins the part, so a view that sees none of the core but other faces of the part still speaks. A face
goes when more views show it outside than inside; a face no view shows (the back of a front, kept by the
segmentation's slab) follows the nearest face a view does show. A trim that would remove less than
``min_share`` of the faces is not made (mask edges, handles). Two parts that no one view shows together
(each top view sees one of them) cannot be told apart this way and stay merged.

Views are rendered at ``width`` px (face ids per pixel); masks are compared there, dilated by ``grow_px``.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy.spatial import cKDTree

from ..data.frames import Frame
from ..data.masks import ArticulationPrediction, Mask2D
from ..data.mesh import TriMesh
from ..data.parts import PartCandidate, TopView


def _resize(mask: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    if mask.shape == shape:
        return mask.astype(bool)
    return cv2.resize(mask.astype(np.uint8), (shape[1], shape[0]), interpolation=cv2.INTER_AREA) > 0


def _grow(mask: np.ndarray, px: int) -> np.ndarray:
    if px <= 0:
        return mask
    k = np.ones((2 * px + 1, 2 * px + 1), np.uint8)
    return cv2.dilate(mask.astype(np.uint8), k) > 0


def _face_votes(fb: np.ndarray, faces: np.ndarray, inside: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per candidate face (index into ``faces``, sorted): visible in ``fb`` at all, and mostly inside ``inside``."""
    sel = np.isin(fb, faces)
    idx = np.searchsorted(faces, fb[sel])
    n_all = np.bincount(idx, minlength=len(faces))
    n_in = np.bincount(idx, weights=inside[sel].astype(float), minlength=len(faces))
    seen = n_all > 0
    return seen, seen & (n_in >= 0.5 * n_all)


def trim_to_prediction(candidate: PartCandidate, best: ArticulationPrediction, best_view: str,
                       predictions: dict[str, list[ArticulationPrediction]], frames: dict[str, Frame],
                       rasterizer, mesh: TriMesh, width: int = 320, grow_px: int = 2,  # noqa: ANN001
                       min_share: float = 0.1) -> PartCandidate:
    """``candidate`` without the faces its top views show outside the predicted part (unchanged when
    less than ``min_share`` of its faces would go); its top-view masks are re-rendered from what is kept."""
    faces = np.unique(np.asarray(candidate.face_ids, np.int64))
    views = [v.frame_id for v in candidate.top_views if v.frame_id in frames]
    if best_view not in views:
        views.insert(0, best_view)
    buffers: dict[str, np.ndarray] = {}
    for fid in views:
        f = frames[fid]
        intr = f.intrinsics.scaled(width, round(f.intrinsics.height * width / f.intrinsics.width))
        buffers[fid] = rasterizer.render_frame(f, intr).face_ids
    fb = buffers[best_view]
    m_best = _grow(_resize(best.mask, fb.shape), grow_px)
    seen, inside = _face_votes(fb, faces, m_best)
    core = inside.copy()
    if not core.any():
        return candidate
    votes_in, votes_out = inside.astype(int), (seen & ~inside).astype(int)
    todo = [fid for fid in views if fid != best_view]
    while todo:  # the view showing most of the part known so far next; what it shows inside joins the part
        px = {fid: np.isin(buffers[fid], faces[core]) for fid in todo}
        fid = max(todo, key=lambda k: int(px[k].sum()))
        todo.remove(fid)
        if px[fid].sum() < 20:
            break  # no view left shows the part: none can say what else the candidate holds
        mask = _covering_prediction(predictions.get(fid, []), px[fid], grow_px)
        if mask is None:
            continue
        seen, inside = _face_votes(buffers[fid], faces, mask)
        votes_in += inside
        votes_out += seen & ~inside
        core |= inside
    drop = votes_out > votes_in
    if drop.sum() < min_share * len(faces):
        return candidate
    drop = _unseen_follow_nearest(mesh.face_centroids[faces], votes_in + votes_out > 0, drop)
    if drop.sum() < min_share * len(faces) or drop.all():
        return candidate
    keep = faces[~drop]
    return _with_faces(candidate, keep, np.asarray(mesh.faces)[keep], buffers)


def _covering_prediction(preds: list[ArticulationPrediction], part_px: np.ndarray, grow_px: int) -> np.ndarray | None:
    """The (grown) mask of the prediction covering most of ``part_px``, when it covers at least half of it."""
    best_cover, mask = 0.0, None
    for p in preds:
        m = _grow(_resize(p.mask, part_px.shape), grow_px)
        cover = float((m & part_px).sum() / part_px.sum())
        if cover > best_cover:
            best_cover, mask = cover, m
    return mask if best_cover >= 0.5 else None


def _unseen_follow_nearest(centroids: np.ndarray, voted: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """``drop`` with each face no view voted on given the verdict of the voted face nearest to it."""
    if voted.all() or not voted.any():
        return drop
    _, nn = cKDTree(centroids[voted]).query(centroids[~voted])
    out = drop.copy()
    out[~voted] = drop[voted][nn]
    return out


def _with_faces(candidate: PartCandidate, keep: np.ndarray, keep_tris: np.ndarray,
                buffers: dict[str, np.ndarray]) -> PartCandidate:
    """The candidate reduced to faces ``keep`` (vertex triples ``keep_tris``): their vertices, and top-view
    masks rendered from them."""
    verts = np.intersect1d(np.asarray(candidate.vertex_ids, np.int64), np.unique(keep_tris))
    views = []
    for v in candidate.top_views:
        fb = buffers.get(v.frame_id)
        mask = Mask2D(frame_id=v.frame_id, mask=np.isin(fb, keep)) if fb is not None else v.mask
        views.append(TopView(frame_id=v.frame_id, iou=v.iou, mask=mask))
    return candidate.model_copy(update={"face_ids": keep, "vertex_ids": verts, "top_views": views})
