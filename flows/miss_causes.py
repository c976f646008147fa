"""Miss-cause breakdown of a converted scene (issue 16): re-run the stages in this process with the
segmentation traced, then attribute every missed / mis-jointed GT part (react3d_core.metrics.miss_causes).

Why a re-run: the flow's cached stage outputs keep the candidates and articulated parts but not the
lifted masks or the Louvain proposals; every stage is deterministic for a given config, so the traced
run reproduces the conversion it explains (its candidate and part counts are returned to check that).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def _gt_faces(gt) -> dict[int, np.ndarray]:  # noqa: ANN001 - GroundTruth
    """Face ids of each movable GT part with the parts below it in the label hierarchy (handles)."""
    out = {}
    for p in gt.movable:
        f = [p.tri_indices] + [c.tri_indices for c in gt.parts if c.label.startswith(p.label + ".") and not c.movable]
        out[p.part_id] = np.unique(np.concatenate(f)).astype(np.int64)
    return out


def trace_scene(scene_path: str, manifest_path: str, config: dict[str, Any]) -> dict[str, Any]:
    """Causes for the conversion of ``scene_path`` (with ``config``) written to ``manifest_path``."""
    from react3d_core.articulation import articulate_candidate
    from react3d_core.articulation.refine import is_flat
    from react3d_core.config import PipelineConfig
    from react3d_core.data.masks import PackedMasks
    from react3d_core.data.parts import InteractiveScene
    from react3d_core.dedup import remove_duplicates
    from react3d_core.fusion.segment import SegmentationTrace, render_work, segment_parts
    from react3d_core.ground_truth import read_articulate3d
    from react3d_core.metrics import evaluate_scene
    from react3d_core.metrics.miss_causes import PredictedJoint, ProposalTrace, StageOutputs, attribute_scene
    from tasks.perception import get_perception, perceive_body
    from tasks.scene import rasterizer, scan_mesh, scene_input
    from tasks.store import get

    cfg = PipelineConfig().with_overrides(config)
    c = cfg.model_dump(mode="json")
    frames_cfg = c["frames"]
    scene = scene_input(scene_path, frames_cfg)
    if scene.gt_dir is None:
        raise ValueError(f"{scene_path}: no ground truth to attribute against")
    mesh_path = str(scene.mesh_path)
    mesh, rast = scan_mesh(mesh_path), rasterizer(mesh_path)
    perc = get_perception(scene, cfg.perception)
    res = get(perceive_body(scene_path, frames_cfg, [f.frame_id for f in scene.frames], c["perception"]), cache=False)
    masks = PackedMasks()
    for fid, ms in res["masks"].items():
        masks.add(fid, ms)
    trace = SegmentationTrace()
    cands = segment_parts(scene, mesh, masks, perc.point_segmenter, cfg, rasterizer=rast, trace=trace)
    parts = []
    for cand in cands:
        views = {v.frame_id for v in cand.top_views}
        parts.append(articulate_candidate(scene, mesh, cand, {f: p for f, p in res["predictions"].items() if f in views},
                                          cfg, rasterizer=rast))
    valid = [p for p in parts if p is not None]
    kept_ids = {p.candidate_id for p in remove_duplicates(valid, cfg.dedup)}
    # faces any frame sees: those with masks were rendered for lifting, the others are rendered here
    seen = [st.faces for st in trace.stats]
    with_masks = {st.frame_id for st in trace.stats}
    seen += [np.unique(render_work(rast, f, cfg).face_ids) for f in scene.frames if f.frame_id not in with_masks]
    st = StageOutputs(
        view_masks=[mf for s in trace.stats for mf in s.mask_faces],
        lifted=[fs for lift in trace.lifts for fs in lift.face_sets],
        seen=np.setdiff1d(np.unique(np.concatenate(seen)) if seen else np.zeros(0, np.int64), [-1]),
        proposals=[ProposalTrace(np.asarray(p.face_ids, np.int64), o.status, o.reseg_faces, o.kept_faces)
                   for p, o in zip(trace.proposals, trace.outcomes)],
        before_duplicates=[np.asarray(k.face_ids, np.int64) for k in trace.before_duplicates],
        candidates=[np.asarray(k.face_ids, np.int64) for k in cands],
        validated=[p is not None for p in parts],
        kept=[k.candidate_id in kept_ids for k in cands],
    )
    manifest = InteractiveScene.load(manifest_path)
    gt = read_articulate3d(scene.gt_dir)
    sm = evaluate_scene(manifest, Path(manifest_path).parent, gt, cfg.evaluation)
    rows = [r for r in sm.parts if abs(r["tau"] - cfg.evaluation.miss_iou) < 1e-9]
    if not rows:  # the miss threshold is not one of the evaluation's: score at it alone
        sm = evaluate_scene(manifest, Path(manifest_path).parent, gt,
                            cfg.evaluation.model_copy(update={"iou_thresholds": (cfg.evaluation.miss_iou,)}))
        rows = sm.parts
    preds = [PredictedJoint(o.articulation, o.initial_articulation, o.obb, np.asarray(o.front_normal, float),
                            is_flat(o.obb, cfg.articulation.flat_ratio)) for o in manifest.objects]
    out = attribute_scene(_gt_faces(gt), {p.part_id: p.articulation for p in gt.movable}, rows, preds, st, cfg.evaluation)
    out["stages"] = {"masks": len(st.view_masks), "proposals": len(st.proposals), "candidates": len(cands),
                     "validated": len(valid), "kept": len(kept_ids), "objects": len(manifest.objects)}
    return out
