"""Per-scene evaluation (paper, Sec. Experiments) and pooled aggregation.

Detection: a prediction is a TP at tau if its vertex IoU with >= 1 GT part is > tau; precision =
TP predictions / predictions, recall = GT parts matched / GT parts. Articulation (joint accuracy,
OE, MD) is scored on TP predictions, each matched to its best-IoU GT part. MOD is cumulative over
GT parts; each matched GT part is judged by its best-IoU prediction among those above tau.

A GT part the scan mostly lacks (its annotation gives its true box and a scan coverage below
``box_below_coverage``, e.g. a black front the depth sensor missed) cannot be scored by vertex IoU: a
prediction of it has no scan vertices to share. Its column uses the front-box IoU instead
(:func:`front_box_iou`); everything else is unchanged (docs/evaluation.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..config.metrics import EvaluationConfig
from ..data.mesh import load_mesh
from ..data.parts import OBB, Articulation, InteractiveScene, load_vertex_ids
from ..errors import InputError
from ..ground_truth.articulate3d import GroundTruth, GTPart
from ..geometry import iou_matrix
from .geometry import axis_error_deg, joint_class, line_distance

METRIC_KEYS = ("precision", "recall", "f1", "joint_acc", "md", "oe", "pdet", "m", "mo", "mod")


@dataclass
class PairScore:
    """Articulation comparison of one prediction with one GT part."""

    type_ok: bool
    oe: float | None  # degrees, only when type_ok
    md: float | None  # metres, only when type_ok and revolute


@dataclass
class ThresholdCounts:
    """Pooled-able counts at one IoU threshold."""

    n_pred: int = 0
    n_gt: int = 0
    tp_pred: int = 0
    gt_matched: int = 0
    type_ok: int = 0
    oe_values: list[float] = field(default_factory=list)
    md_values: list[float] = field(default_factory=list)
    m: int = 0
    mo: int = 0
    mod: int = 0


@dataclass
class SceneMetrics:
    """Everything measured on one scene; ``parts`` holds one row per GT part per threshold."""

    scene: str
    n_gt: int
    n_pred: int
    counts: dict[str, ThresholdCounts]
    parts: list[dict[str, Any]]
    frames: int | None = None
    faces: int | None = None
    wall_s: float | None = None
    peak_rss_mb: float | None = None
    stages: dict[str, float] = field(default_factory=dict)


def tau_key(tau: float) -> str:
    return f"{tau:g}" if tau != int(tau) else f"{tau:.1f}"


def compare_joints(pred: Articulation, gt: Articulation, config: EvaluationConfig) -> PairScore:
    """Type on the 3-way taxonomy; OE and MD only for a correct type (MD for revolute only)."""
    ok = joint_class(pred, config.horizontal_deg) == joint_class(gt, config.horizontal_deg)
    if not ok:
        return PairScore(False, None, None)
    oe = axis_error_deg(pred.axis, gt.axis)
    md = line_distance(pred.origin, pred.axis, gt.origin, gt.axis) if gt.joint_type == "revolute" else None
    return PairScore(True, oe, md)


def front_box_iou(pred: OBB, gt: OBB, slab_tol: float = 0.05) -> float:
    """IoU of two boxes as fronts: their outlines projected on the GT box's front plane (spanned by its
    two longest sides), 0 unless the predicted box lies within the GT slab (its extent along the GT's
    shortest side) grown by ``slab_tol`` on both sides (a misplaced plane or a whole-cabinet box)."""
    import cv2

    R = gt.R
    ext = np.asarray(gt.extents, float)
    rel = pred.corners() - np.asarray(gt.center, float)
    along = rel @ R[:, 2]
    half = ext[2] / 2 + slab_tol
    if along.min() < -half - 1e-9 or along.max() > half + 1e-9:
        return 0.0
    hull = cv2.convexHull((rel @ R[:, :2]).astype(np.float32))
    a, b = ext[0] / 2, ext[1] / 2
    rect = np.array([[-a, -b], [a, -b], [a, b], [-a, b]], np.float32)
    area_p = float(cv2.contourArea(hull))
    if area_p <= 0.0:
        return 0.0
    inter, _ = cv2.intersectConvexConvex(hull, rect)
    union = area_p + 4 * a * b - float(inter)
    return float(inter) / union if union > 0 else 0.0


def _gt_diagonals(gt_sets: list[np.ndarray], vertices: np.ndarray | None) -> list[float | None]:
    out: list[float | None] = []
    for s in gt_sets:
        if vertices is None or len(s) == 0:
            out.append(None)
            continue
        if s.max() >= len(vertices):
            raise InputError(None, f"GT vertex id {int(s.max())} beyond the scan mesh ({len(vertices)} vertices)")
        v = vertices[s]
        out.append(float(np.linalg.norm(v.max(0) - v.min(0))))
    return out


def evaluate_sets(
    pred_sets: list[np.ndarray],
    pred_arts: list[Articulation],
    gt_ids: list[int],
    gt_sets: list[np.ndarray],
    gt_arts: list[Articulation],
    vertices: np.ndarray | None,
    config: EvaluationConfig,
    scene: str = "",
    pred_boxes: list[OBB] | None = None,
    gt_boxes: list[OBB | None] | None = None,
) -> SceneMetrics:
    """Core of :func:`evaluate_scene` on plain arrays (what the tests drive by hand).

    ``gt_boxes[j]`` (given only for GT parts the scan lacks) switches GT part j to front-box IoU with
    ``pred_boxes`` (:func:`front_box_iou`); its diagonal for +MOD is then the box's."""
    iou = iou_matrix(pred_sets, gt_sets)
    diags = _gt_diagonals(gt_sets, vertices)
    boxed = [gt_boxes is not None and gt_boxes[j] is not None for j in range(len(gt_sets))]
    if any(boxed):
        if pred_boxes is None or len(pred_boxes) != len(pred_sets):
            raise ValueError("GT parts scored by box need a box per prediction")
        for j in np.flatnonzero(boxed):
            gb = gt_boxes[j]  # type: ignore[index]
            iou[:, j] = [front_box_iou(pb, gb, config.box_slab_tol) for pb in pred_boxes]
            diags[j] = float(np.linalg.norm(gb.extents))
    n_pred, n_gt = len(pred_sets), len(gt_sets)
    pairs = {(i, j): compare_joints(pred_arts[i], gt_arts[j], config) for i in range(n_pred) for j in range(n_gt) if iou[i, j] > 0}
    counts: dict[str, ThresholdCounts] = {}
    rows: list[dict[str, Any]] = []
    for tau in config.iou_thresholds:
        c = ThresholdCounts(n_pred=n_pred, n_gt=n_gt)
        above = iou > tau
        for i in np.flatnonzero(above.any(axis=1)):  # TP predictions -> best GT
            c.tp_pred += 1
            ps = pairs[(int(i), int(np.argmax(iou[i])))]
            if ps.type_ok:
                c.type_ok += 1
                c.oe_values.append(ps.oe)  # type: ignore[arg-type]
                if ps.md is not None:
                    c.md_values.append(ps.md)
        for j in range(n_gt):  # MOD, cumulative over GT parts
            row: dict[str, Any] = {
                "scene": scene, "tau": float(tau), "gt_part": int(gt_ids[j]), "gt_type": joint_class(gt_arts[j], config.horizontal_deg),
                "diag": diags[j], "matched": False, "pred": None, "iou": float(iou[:, j].max()) if n_pred else 0.0,
                "pred_type": None, "type_ok": False, "oe": None, "md": None, "mo": False, "mod": False,
                "scored_by": "box" if boxed[j] else "vertices",
            }
            if n_pred and above[:, j].any():
                i = int(np.argmax(np.where(above[:, j], iou[:, j], -1.0)))
                ps = pairs[(i, j)]
                c.gt_matched += 1
                mo = ps.type_ok and ps.oe is not None and ps.oe < config.oe_deg
                if ps.md is None:
                    mod = mo  # prismatic skips MD
                else:
                    mod = mo and diags[j] is not None and ps.md < config.md_factor * diags[j]
                c.m += ps.type_ok
                c.mo += mo
                c.mod += mod
                row.update(matched=True, pred=i, pred_type=joint_class(pred_arts[i], config.horizontal_deg), type_ok=ps.type_ok,
                           oe=ps.oe, md=ps.md, mo=bool(mo), mod=bool(mod))
            rows.append(row)
        counts[tau_key(tau)] = c
    return SceneMetrics(scene=scene, n_gt=n_gt, n_pred=n_pred, counts=counts, parts=rows)


def box_scored_box(part: GTPart, n_vertices: int, config: EvaluationConfig) -> OBB | None:
    """The part's box when it is scored by box (it has one, and the scan holds under
    ``box_below_coverage`` of its surface or none of its vertices), else None."""
    if part.obb is None:
        return None
    if n_vertices == 0 or (part.coverage is not None and part.coverage < config.box_below_coverage):
        return part.obb
    return None


def evaluate_scene(
    pred: InteractiveScene, pred_dir: Path, gt: GroundTruth, config: EvaluationConfig, vertices: np.ndarray | None = None
) -> SceneMetrics:
    """Evaluate one converted scene against its Articulate3D ground truth. ``vertices`` (the scan mesh
    the ids refer to) is loaded from ``pred.input_mesh`` when not given; it only feeds the GT part
    diagonals for +MOD."""
    pred_dir = Path(pred_dir)
    pred_sets, pred_arts = [], []
    for obj in pred.objects:
        if obj.source_vertex_ids is None:
            raise InputError(pred_dir / "scene.json", f"object {obj.object_id} has no source_vertex_ids; cannot score it")
        pred_sets.append(load_vertex_ids(pred_dir / obj.source_vertex_ids))
        pred_arts.append(obj.articulation)
    gt_sets_d = gt.movable_vertex_sets(include_children=True)
    gt_ids = list(gt_sets_d)
    by_id = {p.part_id: p for p in gt.movable}
    gt_boxes = [box_scored_box(by_id[k], len(gt_sets_d[k]), config) for k in gt_ids]
    if vertices is None:
        mesh_path = Path(pred.input_mesh)
        mesh_path = mesh_path if mesh_path.is_absolute() else pred_dir / mesh_path
        vertices = load_mesh(mesh_path).vertices
    sm = evaluate_sets(pred_sets, pred_arts, gt_ids, [gt_sets_d[k] for k in gt_ids], [by_id[k].articulation for k in gt_ids],
                       vertices, config, scene=pred.scene_id, pred_boxes=[o.obb for o in pred.objects], gt_boxes=gt_boxes)
    sm.faces = gt.total_faces
    sm.stages = {k: float(v) for k, v in pred.timings.items()}
    return sm


def _ratio(a: float, b: float) -> float | None:
    return a / b if b > 0 else None


def _mean(v: list[float]) -> float | None:
    return float(np.mean(v)) if v else None


def summarize(c: ThresholdCounts) -> dict[str, float | None]:
    """The ten reported numbers from (pooled) counts; undefined ones are None."""
    p, r = _ratio(c.tp_pred, c.n_pred), _ratio(c.gt_matched, c.n_gt)
    if p is None and r is None:
        f1 = None
    elif not p or not r:
        f1 = 0.0
    else:
        f1 = 2 * p * r / (p + r)
    return {
        "precision": p, "recall": r, "f1": f1, "joint_acc": _ratio(c.type_ok, c.tp_pred),
        "md": _mean(c.md_values), "oe": _mean(c.oe_values),
        "pdet": r, "m": _ratio(c.m, c.n_gt), "mo": _ratio(c.mo, c.n_gt), "mod": _ratio(c.mod, c.n_gt),
    }


def pool(scenes: list[SceneMetrics]) -> dict[str, ThresholdCounts]:
    """Sum counts over scenes, concatenate OE/MD samples."""
    out: dict[str, ThresholdCounts] = {}
    for s in scenes:
        for k, c in s.counts.items():
            t = out.setdefault(k, ThresholdCounts())
            t.n_pred += c.n_pred
            t.n_gt += c.n_gt
            t.tp_pred += c.tp_pred
            t.gt_matched += c.gt_matched
            t.type_ok += c.type_ok
            t.oe_values += c.oe_values
            t.md_values += c.md_values
            t.m += c.m
            t.mo += c.mo
            t.mod += c.mod
    return out


def aggregate(scenes: list[SceneMetrics]) -> dict[str, dict[str, float | None]]:
    """Pooled over all parts of all scenes: {tau_key: {metric: value}}."""
    return {k: summarize(c) for k, c in pool(scenes).items()}


def to_json_dict(scenes: list[SceneMetrics]) -> dict[str, Any]:
    """The stable report shape documented in docs/evaluation.md."""
    return {
        "aggregate": aggregate(scenes),
        "scenes": [
            {
                "scene": s.scene, "n_gt": s.n_gt, "n_pred": s.n_pred, "frames": s.frames, "faces": s.faces,
                "wall_s": s.wall_s, "peak_rss_mb": s.peak_rss_mb, "stages": dict(s.stages),
                **{k: summarize(c) for k, c in s.counts.items()},
            }
            for s in scenes
        ],
    }
