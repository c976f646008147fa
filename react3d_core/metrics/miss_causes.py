"""Miss-cause breakdown: for each GT part that is missed or scored below IoU 0.5, the stage
where it was lost; for each matched part with a large axis or hinge error, the cause where it can be told.

Why: F1 and OE say *that* parts are lost, not *where*; fixing the pipeline needs the stage. The trace is
computed on the scan's faces from the stages' own outputs (:class:`StageOutputs`, filled by the caller
from a traced run), in pipeline order; the first stage after which no output still holds the part
(face IoU >= ``cause_stage_iou`` with the part's *seen* faces, those in any frame's view) is the cause:

``coincident_gt``          the GT part shares its place with another GT part (their boxes overlap by more
                           than half the smaller): two objects stacked in one spot by the scene
                           generator, whose surfaces z-fight; no pipeline can return both
``no_scan_surface``        the GT part is scored by its box (the scan holds under ``box_below_coverage``
                           of its surface: a dark front the depth sensor missed) and no prediction's box
                           matches it; the stage trace of its remaining surface is kept as ``trace_cause``
``not_seen``               no frame sees the part at all
``not_masked``             fewer than ``cause_min_views`` 2D masks lie on the part (perception; judged on
                           the GT part-id images where the scene has them, else on the scan's faces)
``off_scan_surface``       masked in the images, but in the scan the masks lie mostly on other surface:
                           the part is not where the images show it (colour misregistered against the
                           mesh). Pixels seen through the front (a glass pane missing from the scan
                           shows the cabinet's inside) are left out of every mask, as lifting does
``filled_through``         masked, but hole filling (meant for missed handles) pulls in other surface
                           within the front's slab, so the filled masks are mostly other surface
``lost_in_lifting``        masked often enough, but fewer masks survive lifting (erosion, occlusion),
                           or the lifted faces cover under half of the part
``lost_in_fusion``         lifted, but no Louvain proposal is the part, merged or split (graph too weak)
``merged``                 a Louvain proposal holds the part together with neighbouring surface
``split``                  the part is cut into several proposals, none of them big enough
``no_top_view``            its proposal got no top-k view (never seen whole enough)
``merged_in_reseg``        re-segmentation grew it into a neighbour (or an earlier candidate took it)
``resegmentation``         re-segmentation returned too little of it
``clipped``                plane clipping cut it below the IoU
``duplicate_dropped``      a candidate held it but the segmentation's duplicate drop removed it
``rejected_by_validation`` no articulation prediction matched the candidate's mask (valid_iou)
``dropped_by_dedup``       assembly's duplicate removal dropped it
``unobserved_geometry``    the final part holds the part's seen surface (area IoU), but the evaluation's
                           vertex IoU is below the threshold: the GT counts surface no frame saw, or
                           vertices crowd on small triangles the part left out (edges, bevels)
``other``                  none of the above

Joint causes (matched parts; OE > ``cause_oe_deg`` or MD > ``cause_md_m``): ``type_wrong``,
``sliding_not_flagged`` (GT slides in the front plane, the part was pulled out of it), ``obb_tilt``
(no side of the part's box is within the threshold of the GT axis: the box is tilted by stray or missing
faces), ``not_refined`` (a non-flat part keeps the predicted axis), ``wrong_obb_axis`` (refinement
snapped to another side of the box), ``far_edge`` (the nearer-edge rule picked the far edge though the
predicted hinge line was nearer the right one), ``wrong_hinge_side`` (the prediction put the hinge on
the other edge and the rule followed it),
``edge_offset`` (neither box edge is on the hinge: the part's outline is off), ``other_origin``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..config.metrics import EvaluationConfig
from ..data.parts import OBB, Articulation
from .geometry import axis_error_deg, joint_class, line_distance

MISS_CAUSES = ("coincident_gt", "no_scan_surface", "not_seen", "not_masked", "off_scan_surface", "filled_through", "lost_in_lifting", "lost_in_fusion", "merged", "split", "no_top_view",
               "merged_in_reseg", "resegmentation", "clipped", "duplicate_dropped", "rejected_by_validation",
               "dropped_by_dedup", "unobserved_geometry", "other")
JOINT_CAUSES = ("type_wrong", "sliding_not_flagged", "obb_tilt", "not_refined", "wrong_obb_axis", "far_edge",
                "wrong_hinge_side", "edge_offset", "other_axis", "other_origin")


@dataclass
class ProposalTrace:
    """One Louvain proposal and what became of it (see ``fusion.segment.ProposalOutcome``)."""

    faces: np.ndarray
    status: str                      # candidate | no_views | claimed | reseg_empty | clip_empty
    reseg_faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    kept_faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


@dataclass
class StageOutputs:
    """Every stage's output as face-id arrays of the scan mesh (what the attribution reads).

    ``view_masks``: faces under each 2D mask of each frame as predicted; ``filled``: the same after
    hole filling (not eroded); ``lifted``: faces each mask was lifted to (filled, eroded); ``seen``:
    faces in any frame's view; ``masked_2d`` (optional): per GT part id, how many masks lie on it in
    the GT part-id images (pixels, independent of the scan); ``face_area`` (optional): area of every
    scan face, to weigh overlaps by surface instead of face count (scan triangles vary in size: a
    door front of 60 large triangles beside edges of 1000 small ones); ``*_pixels`` (optional, parallel
    to the mask face sets): pixels of the mask on each of its faces, so that a mask's share on the part
    is counted in pixels (one bled pixel on a wall's big triangle is one pixel, not the triangle);
    ``before_duplicates`` / ``candidates``: candidates before / after the segmentation's duplicate drop;
    ``validated[i]``: candidate i passed validation; ``kept[i]``: it survived assembly's dedup.
    """

    view_masks: list[np.ndarray]
    filled: list[np.ndarray]
    lifted: list[np.ndarray]
    seen: np.ndarray
    proposals: list[ProposalTrace]
    before_duplicates: list[np.ndarray]
    candidates: list[np.ndarray]
    validated: list[bool]
    kept: list[bool]
    masked_2d: dict[int, int] | None = None
    face_area: np.ndarray | None = None
    view_pixels: list[np.ndarray] | None = None
    filled_pixels: list[np.ndarray] | None = None
    lifted_pixels: list[np.ndarray] | None = None


def _size(ids: np.ndarray, w: np.ndarray | None) -> float:
    """Area of a face set (face count without areas)."""
    return float(w[ids].sum()) if w is not None else float(len(ids))


def _overlaps(sets: list[np.ndarray], part: np.ndarray, w: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per set: area of S & P, area of S, IoU with P (P and every S unique face ids; areas by ``w``)."""
    inter = np.array([_size(np.intersect1d(s, part, assume_unique=True), w) for s in sets], float)
    size = np.array([_size(s, w) for s in sets], float)
    union = size + _size(part, w) - inter
    return inter, size, np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)


def _best(sets: list[np.ndarray], part: np.ndarray, w: np.ndarray | None = None) -> tuple[int, float]:
    if not sets:
        return -1, 0.0
    iou = _overlaps(sets, part, w)[2]
    i = int(np.argmax(iou))
    return i, float(iou[i])


def _on_part(sets: list[np.ndarray], part: np.ndarray, cfg: EvaluationConfig, w: np.ndarray | None = None,
             pixels: list[np.ndarray] | None = None) -> int:
    """How many masks lie on the part: mostly on it (share of the mask's pixels, else of its faces'
    area) and covering a share of its surface."""
    if not sets or not len(part):
        return 0
    inter, size, _ = _overlaps(sets, part, w)
    if pixels is not None:
        on = [np.isin(s, part, assume_unique=True) for s in sets]
        inter_px = np.array([float(px[o].sum()) for px, o in zip(pixels, on)])
        size_px = np.array([float(px.sum()) for px in pixels])
        prec = np.divide(inter_px, size_px, out=np.zeros_like(inter_px), where=size_px > 0)
    else:
        prec = np.divide(inter, size, out=np.zeros_like(inter), where=size > 0)
    return int(((prec >= cfg.cause_view_precision) & (inter >= cfg.cause_view_coverage * _size(part, w))).sum())


def miss_cause(gt_faces: np.ndarray, eval_iou: float, st: StageOutputs, cfg: EvaluationConfig,
               part_id: int | None = None) -> tuple[str, dict[str, Any]]:
    """The stage where a GT part (all its faces, handles included) was lost, and the numbers that say so."""
    w = st.face_area
    part = np.intersect1d(np.unique(np.asarray(gt_faces, np.int64)), st.seen)
    area = _size(part, w)
    info: dict[str, Any] = {"seen_faces": int(len(part)), "eval_iou": float(eval_iou)}
    if not len(part):
        return "not_seen", info
    thr = cfg.cause_stage_iou
    # downstream first: a later stage holding the part tells where it went missing after that
    ci, c_iou = _best(st.candidates, part, w)
    info["candidate_iou"] = round(c_iou, 3)
    if c_iou >= thr:
        holders = [i for i, s in enumerate(st.candidates) if _overlaps([s], part, w)[2][0] >= thr]
        if not any(st.validated[i] for i in holders):
            return "rejected_by_validation", info
        if not any(st.kept[i] for i in holders):
            return "dropped_by_dedup", info
        return ("unobserved_geometry" if eval_iou < cfg.miss_iou else "other"), info
    if _best(st.before_duplicates, part, w)[1] >= thr:
        return "duplicate_dropped", info
    n_masked = _on_part(st.view_masks, part, cfg, w, st.view_pixels)
    n_filled = _on_part(st.filled, part, cfg, w, st.filled_pixels)
    n_lifted = _on_part(st.lifted, part, cfg, w, st.lifted_pixels)
    lifted_all = np.unique(np.concatenate(st.lifted)) if st.lifted else np.zeros(0, np.int64)
    lifted_cover = _size(np.intersect1d(lifted_all, part, assume_unique=True), w) / area
    info.update(masked_views=n_masked, filled_views=n_filled, lifted_views=n_lifted, lifted_cover=round(lifted_cover, 3))
    if st.masked_2d is not None and part_id is not None:
        info["masked_views_2d"] = n2d = int(st.masked_2d.get(part_id, 0))
        if n2d < cfg.cause_min_views:
            return "not_masked", info
        if n_masked < cfg.cause_min_views:
            return "off_scan_surface", info
    elif n_masked < cfg.cause_min_views:
        return "not_masked", info
    if n_filled < cfg.cause_min_views:
        return "filled_through", info
    if n_lifted < cfg.cause_min_views or lifted_cover < 0.5:
        return "lost_in_lifting", info
    props = [p.faces for p in st.proposals]
    pi, p_iou = _best(props, part, w)
    info["proposal_iou"] = round(p_iou, 3)
    if p_iou < thr:
        if props:
            inter, size, _ = _overlaps(props, part, w)
            prec = np.divide(inter, size, out=np.zeros_like(inter), where=size > 0)
            if ((inter >= thr * area) & (prec < thr)).any():
                return "merged", info
            inside = prec >= thr
            held = np.unique(np.concatenate([props[i] for i in np.flatnonzero(inside)])) if inside.any() else lifted_all[:0]
            if inside.sum() >= 2 and _size(np.intersect1d(held, part, assume_unique=True), w) >= thr * area:
                return "split", info
        return "lost_in_fusion", info
    p = st.proposals[pi]
    info["proposal_status"] = p.status
    if p.status == "no_views":
        return "no_top_view", info
    if p.status == "claimed":
        return "merged_in_reseg", info
    r_inter, r_size, r_iou = (x[0] for x in _overlaps([np.unique(p.reseg_faces)], part, w))
    info["reseg_iou"] = round(float(r_iou), 3)
    if p.status == "reseg_empty" or r_iou < thr:
        grown = r_inter >= thr * area and r_size > 0 and r_inter / r_size < thr
        return ("merged_in_reseg" if grown else "resegmentation"), info
    return "clipped", info


@dataclass
class PredictedJoint:
    """What the joint cause needs of a prediction: refined and predicted joints and the part's box."""

    articulation: Articulation
    initial: Articulation | None
    obb: OBB
    front_normal: np.ndarray
    flat: bool


def _obb_sides(obb: OBB) -> list[np.ndarray]:
    return [obb.R[:, k] for k in range(3)]


def joint_causes(pred: PredictedJoint, gt: Articulation, cfg: EvaluationConfig) -> list[str]:
    """Causes of a matched part's joint error (empty when OE <= ``cause_oe_deg`` and MD <= ``cause_md_m``)."""
    a = pred.articulation
    if joint_class(a, cfg.horizontal_deg) != joint_class(gt, cfg.horizontal_deg):
        return ["type_wrong"]
    out = []
    gt_axis = np.asarray(gt.axis, float)
    n = np.asarray(pred.front_normal, float)
    if axis_error_deg(a.axis, gt_axis) > cfg.cause_oe_deg:
        tilt = min(axis_error_deg(s, gt_axis) for s in _obb_sides(pred.obb))
        if (gt.joint_type == "prismatic" and abs(float(gt_axis @ n)) < np.cos(np.radians(45.0))
                and abs(float(np.dot(a.axis, n))) >= np.cos(np.radians(45.0))):
            out.append("sliding_not_flagged")
        elif tilt > cfg.cause_oe_deg:
            out.append("obb_tilt")
        elif not pred.flat:
            out.append("not_refined")
        elif min(axis_error_deg(a.axis, s) for s in _obb_sides(pred.obb)) <= cfg.cause_oe_deg:
            out.append("wrong_obb_axis")
        else:
            out.append("other_axis")
    if gt.joint_type == "revolute" and line_distance(a.origin, a.axis, gt.origin, gt_axis) > cfg.cause_md_m:
        R, ext = pred.obb.R, np.asarray(pred.obb.extents, float)
        k = 0 if abs(float(np.dot(a.axis, R[:, 0]))) >= abs(float(np.dot(a.axis, R[:, 1]))) else 1
        m, half = R[:, 1 - k], ext[1 - k] / 2
        c = np.asarray(pred.obb.center, float)
        edges = [c + half * m, c - half * m]
        d_gt = [line_distance(e, R[:, k], gt.origin, gt_axis) for e in edges]
        chosen = int(np.argmin([np.linalg.norm(np.asarray(a.origin) - e) for e in edges]))
        if d_gt[1 - chosen] <= cfg.cause_md_m < d_gt[chosen]:
            ini = pred.initial
            by_pred = (None if ini is None else
                       [line_distance(e, R[:, k], ini.origin, ini.axis) for e in edges])
            out.append("far_edge" if by_pred is not None and by_pred[1 - chosen] < by_pred[chosen] else "wrong_hinge_side")
        elif min(d_gt) > cfg.cause_md_m:
            out.append("edge_offset")
        else:
            out.append("other_origin")
    return out


def coincident_parts(boxes: dict[int, tuple[np.ndarray, np.ndarray]], share: float = 0.5) -> set[int]:
    """GT parts whose axis-aligned box overlaps another GT part's by more than ``share`` of the smaller
    volume (a flat part's box is grown to 1 cm thick so coplanar doors count)."""
    ids = list(boxes)
    if len(ids) < 2:
        return set()
    lo = np.array([boxes[i][0] for i in ids], float)
    hi = np.array([boxes[i][1] for i in ids], float)
    pad = np.maximum(0.01 - (hi - lo), 0.0) / 2
    lo, hi = lo - pad, hi + pad
    inter = np.prod(np.clip(np.minimum(hi[:, None], hi[None]) - np.maximum(lo[:, None], lo[None]), 0, None), axis=2)
    vol = np.prod(hi - lo, axis=1)
    over = inter > share * np.minimum(vol[:, None], vol[None])
    np.fill_diagonal(over, False)
    return {ids[k] for k in np.flatnonzero(over.any(1))}


def empty_counts() -> dict[str, dict[str, int]]:
    """The stable JSON shape: every cause key present, zero when it did not occur."""
    return {"miss": {k: 0 for k in MISS_CAUSES}, "joint": {k: 0 for k in JOINT_CAUSES}}


def attribute_scene(gt_faces: dict[int, np.ndarray], gt_arts: dict[int, Articulation], rows: list[dict[str, Any]],
                    preds: list[PredictedJoint], st: StageOutputs, cfg: EvaluationConfig,
                    coincident: set[int] | None = None) -> dict[str, Any]:
    """Causes for one scene. ``rows``: the evaluation's per-GT-part rows at one threshold
    (``gt_part``, ``iou``, ``matched``, ``pred``, ``oe``, ``md``); ``preds`` indexed like ``row['pred']``;
    ``coincident``: GT parts stacked on another GT part (:func:`coincident_parts`), a fault of the data.

    Returns ``{"counts": {"miss": {cause: n}, "joint": {cause: n}}, "parts": [...]}``: one entry per
    traced part with its ``gt_part``, ``kind`` (miss | joint), ``causes`` and the stage numbers."""
    counts = empty_counts()
    parts = []
    for r in rows:
        pid = int(r["gt_part"])
        if not r["matched"] or r["iou"] < cfg.miss_iou:
            if coincident and pid in coincident:
                cause, info = "coincident_gt", {"eval_iou": float(r["iou"])}
            else:
                cause, info = miss_cause(gt_faces[pid], float(r["iou"]), st, cfg, pid)
                if r.get("scored_by") == "box":
                    cause, info = "no_scan_surface", {**info, "trace_cause": cause}
            counts["miss"][cause] += 1
            parts.append({"gt_part": pid, "kind": "miss", "causes": [cause], **info})
            continue
        oe, md = r.get("oe"), r.get("md")
        bad = (not r.get("type_ok", True)) or (oe is not None and oe > cfg.cause_oe_deg) or (md is not None and md > cfg.cause_md_m)
        if not bad or r.get("pred") is None:
            continue
        causes = joint_causes(preds[int(r["pred"])], gt_arts[pid], cfg)
        for c in causes:
            counts["joint"][c] += 1
        parts.append({"gt_part": pid, "kind": "joint", "causes": causes, "oe": oe, "md": md})
    return {"counts": counts, "parts": parts}


def pool_counts(scenes: list[dict[str, Any]]) -> dict[str, dict[str, int]]:
    """Sum the per-scene cause counts (every key present)."""
    out = empty_counts()
    for s in scenes:
        for kind in out:
            for k, v in s.get("counts", {}).get(kind, {}).items():
                out[kind][k] = out[kind].get(k, 0) + int(v)
    return out
