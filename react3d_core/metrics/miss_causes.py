"""Miss-cause breakdown (issue 16): for each GT part that is missed or scored below IoU 0.5, the stage
where it was lost; for each matched part with a large axis or hinge error, the cause where it can be told.

Why: F1 and OE say *that* parts are lost, not *where*; fixing the pipeline needs the stage. The trace is
computed on the scan's faces from the stages' own outputs (:class:`StageOutputs`, filled by the caller
from a traced run), in pipeline order; the first stage after which no output still holds the part
(face IoU >= ``cause_stage_iou`` with the part's *seen* faces, those in any frame's view) is the cause:

``not_seen``               no frame sees the part at all
``not_masked``             fewer than ``cause_min_views`` 2D masks lie on the part (perception)
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
``unobserved_geometry``    the final part holds its seen faces, the GT also counts surface nobody saw
``other``                  none of the above

Joint causes (matched parts; OE > ``cause_oe_deg`` or MD > ``cause_md_m``): ``type_wrong``,
``sliding_not_flagged`` (GT slides in the front plane, the part was pulled out of it), ``obb_tilt``
(no side of the part's box is within the threshold of the GT axis: the box is tilted by stray or missing
faces), ``not_refined`` (a non-flat part keeps the predicted axis), ``wrong_obb_axis`` (refinement
snapped to another side of the box), ``far_edge`` (the nearer-edge rule picked the far edge),
``edge_offset`` (neither box edge is on the hinge: the part's outline is off), ``other_origin``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..config.evaluation import EvaluationConfig
from ..data.parts import OBB, Articulation
from .geometry import axis_error_deg, joint_class, line_distance

MISS_CAUSES = ("not_seen", "not_masked", "lost_in_lifting", "lost_in_fusion", "merged", "split", "no_top_view",
               "merged_in_reseg", "resegmentation", "clipped", "duplicate_dropped", "rejected_by_validation",
               "dropped_by_dedup", "unobserved_geometry", "other")
JOINT_CAUSES = ("type_wrong", "sliding_not_flagged", "obb_tilt", "not_refined", "wrong_obb_axis", "far_edge",
                "edge_offset", "other_axis", "other_origin")


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

    ``view_masks``: faces under each usable 2D mask of each frame (hole-filled, not eroded);
    ``lifted``: faces each mask was lifted to (eroded); ``seen``: faces in any frame's view;
    ``before_duplicates`` / ``candidates``: candidates before / after the segmentation's duplicate drop;
    ``validated[i]``: candidate i passed validation; ``kept[i]``: it survived assembly's dedup.
    """

    view_masks: list[np.ndarray]
    lifted: list[np.ndarray]
    seen: np.ndarray
    proposals: list[ProposalTrace]
    before_duplicates: list[np.ndarray]
    candidates: list[np.ndarray]
    validated: list[bool]
    kept: list[bool]


def _overlaps(sets: list[np.ndarray], part: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per set: |S & P|, |S|, IoU with P (P and every S unique face ids)."""
    inter = np.array([len(np.intersect1d(s, part, assume_unique=True)) for s in sets], float)
    size = np.array([len(s) for s in sets], float)
    union = size + len(part) - inter
    return inter, size, np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)


def _best(sets: list[np.ndarray], part: np.ndarray) -> tuple[int, float]:
    if not sets:
        return -1, 0.0
    iou = _overlaps(sets, part)[2]
    i = int(np.argmax(iou))
    return i, float(iou[i])


def _on_part(sets: list[np.ndarray], part: np.ndarray, cfg: EvaluationConfig) -> int:
    """How many sets lie on the part: mostly its faces and covering a share of it."""
    if not sets or not len(part):
        return 0
    inter, size, _ = _overlaps(sets, part)
    prec = np.divide(inter, size, out=np.zeros_like(inter), where=size > 0)
    return int(((prec >= cfg.cause_view_precision) & (inter >= cfg.cause_view_coverage * len(part))).sum())


def miss_cause(gt_faces: np.ndarray, eval_iou: float, st: StageOutputs, cfg: EvaluationConfig) -> tuple[str, dict[str, Any]]:
    """The stage where a GT part (all its faces, handles included) was lost, and the numbers that say so."""
    part = np.intersect1d(np.unique(np.asarray(gt_faces, np.int64)), st.seen)
    info: dict[str, Any] = {"seen_faces": int(len(part)), "eval_iou": float(eval_iou)}
    if not len(part):
        return "not_seen", info
    thr = cfg.cause_stage_iou
    # downstream first: a later stage holding the part tells where it went missing after that
    ci, c_iou = _best(st.candidates, part)
    info["candidate_iou"] = round(c_iou, 3)
    if c_iou >= thr:
        holders = [i for i, s in enumerate(st.candidates) if _overlaps([s], part)[2][0] >= thr]
        if not any(st.validated[i] for i in holders):
            return "rejected_by_validation", info
        if not any(st.kept[i] for i in holders):
            return "dropped_by_dedup", info
        return ("unobserved_geometry" if eval_iou < cfg.miss_iou else "other"), info
    if _best(st.before_duplicates, part)[1] >= thr:
        return "duplicate_dropped", info
    n_masked = _on_part(st.view_masks, part, cfg)
    n_lifted = _on_part(st.lifted, part, cfg)
    lifted_cover = len(np.intersect1d(np.unique(np.concatenate(st.lifted)) if st.lifted else np.zeros(0, np.int64), part,
                                      assume_unique=True)) / len(part)
    info.update(masked_views=n_masked, lifted_views=n_lifted, lifted_cover=round(lifted_cover, 3))
    if n_masked < cfg.cause_min_views:
        return "not_masked", info
    if n_lifted < cfg.cause_min_views or lifted_cover < 0.5:
        return "lost_in_lifting", info
    props = [p.faces for p in st.proposals]
    pi, p_iou = _best(props, part)
    info["proposal_iou"] = round(p_iou, 3)
    if p_iou < thr:
        if props:
            inter, size, _ = _overlaps(props, part)
            prec = np.divide(inter, size, out=np.zeros_like(inter), where=size > 0)
            if ((inter >= thr * len(part)) & (prec < thr)).any():
                return "merged", info
            inside = prec >= thr
            if inside.sum() >= 2 and len(np.intersect1d(np.unique(np.concatenate([props[i] for i in np.flatnonzero(inside)])),
                                                        part)) >= thr * len(part):
                return "split", info
        return "lost_in_fusion", info
    p = st.proposals[pi]
    info["proposal_status"] = p.status
    if p.status == "no_views":
        return "no_top_view", info
    if p.status == "claimed":
        return "merged_in_reseg", info
    r_inter, r_size, r_iou = (x[0] for x in _overlaps([p.reseg_faces], part))
    info["reseg_iou"] = round(float(r_iou), 3)
    if p.status == "reseg_empty" or r_iou < thr:
        grown = r_inter >= thr * len(part) and r_size > 0 and r_inter / r_size < thr
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
            out.append("far_edge")
        elif min(d_gt) > cfg.cause_md_m:
            out.append("edge_offset")
        else:
            out.append("other_origin")
    return out


def empty_counts() -> dict[str, dict[str, int]]:
    """The stable JSON shape: every cause key present, zero when it did not occur."""
    return {"miss": {k: 0 for k in MISS_CAUSES}, "joint": {k: 0 for k in JOINT_CAUSES}}


def attribute_scene(gt_faces: dict[int, np.ndarray], gt_arts: dict[int, Articulation], rows: list[dict[str, Any]],
                    preds: list[PredictedJoint], st: StageOutputs, cfg: EvaluationConfig) -> dict[str, Any]:
    """Causes for one scene. ``rows``: the evaluation's per-GT-part rows at one threshold
    (``gt_part``, ``iou``, ``matched``, ``pred``, ``oe``, ``md``); ``preds`` indexed like ``row['pred']``.

    Returns ``{"counts": {"miss": {cause: n}, "joint": {cause: n}}, "parts": [...]}``: one entry per
    traced part with its ``gt_part``, ``kind`` (miss | joint), ``causes`` and the stage numbers."""
    counts = empty_counts()
    parts = []
    for r in rows:
        pid = int(r["gt_part"])
        if not r["matched"] or r["iou"] < cfg.miss_iou:
            cause, info = miss_cause(gt_faces[pid], float(r["iou"]), st, cfg)
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
