"""Miss-cause breakdown of a converted scene: re-run the stages in this process with the
segmentation traced, then attribute every missed / mis-jointed GT part (react3d_core.metrics.miss_causes).

Why a re-run: the flow's cached stage outputs keep the candidates and articulated parts but not the
lifted masks or the Louvain proposals; every stage is deterministic for a given config, so the traced
run reproduces the conversion it explains (its candidate and part counts are returned to check that).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from react3d_core.config import PipelineConfig
    from react3d_core.data.frames import SceneInput
    from react3d_core.data.masks import Mask2D
    from react3d_core.ground_truth import GroundTruth


def gt_part_faces(gt: GroundTruth) -> dict[int, np.ndarray]:
    """Face ids of each movable GT part with the parts below it in the label hierarchy (handles)."""
    out = {}
    for p in gt.movable:
        f = [p.tri_indices] + [c.tri_indices for c in gt.parts if c.label.startswith(p.label + ".") and not c.movable]
        out[p.part_id] = np.unique(np.concatenate(f)).astype(np.int64)
    return out


def masks_on_parts_2d(scene: SceneInput, masks: Mapping[str, Sequence[Mask2D]], cfg: PipelineConfig) -> dict[int, int] | None:
    """Per movable GT part, how many masks lie on it in the GT part-id images (pixels: >= ``cause_view_precision``
    of the mask on the part, >= ``cause_view_coverage`` of the part's pixels); None without such images
    (rendering GT faces of the scan instead would see what the scan sees, not what the images show)."""
    if not scene.frames or any(f.part_ids is None or not f.part_ids.path.is_file() for f in scene.frames):
        return None
    from react3d_core.fusion.lift import resize_mask
    from react3d_core.perception.oracle import OracleModel

    om = OracleModel(scene, cfg.perception.oracle)
    top = max([p.part_id for p in om.gt.parts] + [0])
    lut = np.full(top + 2, -1, np.int64)  # GT part id -> the movable part it moves with (handles -> door)
    for pid, own in om.owner.items():
        lut[pid] = own
    ev = cfg.evaluation
    out: dict[int, int] = {}
    for f in scene.frames:
        ms = masks.get(f.frame_id, [])
        if not ms:
            continue
        img = om.part_image(f)
        own = np.where((img >= 0) & (img <= top), lut[np.clip(img, 0, top)], -1)
        region = np.bincount(own[own >= 0].ravel(), minlength=top + 1)
        for mk in ms:
            m = resize_mask(mk.mask, own.shape)
            under = own[m]
            cnt = np.bincount(under[under >= 0], minlength=top + 1)
            ok = (cnt >= ev.cause_view_precision * max(int(m.sum()), 1)) & (cnt >= ev.cause_view_coverage * region) & (cnt > 0)
            for pid in np.flatnonzero(ok):
                out[int(pid)] = out.get(int(pid), 0) + 1
    return out


def trace_scene(scene_path: str, manifest_path: str, config: dict[str, Any]) -> dict[str, Any]:
    """Causes for the conversion of ``scene_path`` (with ``config``) written to ``manifest_path``."""
    from react3d_core.articulation.refine import is_flat
    from react3d_core.config import PipelineConfig
    from react3d_core.data.parts import InteractiveScene
    from react3d_core.dedup import remove_duplicates
    from react3d_core.fusion.lift import filled, prepare_mask, resize_mask
    from react3d_core.fusion.segment import SegmentationTrace, render_work, segment_parts
    from react3d_core.ground_truth import read_articulate3d
    from react3d_core.metrics import evaluate_scene
    from react3d_core.metrics.miss_causes import (PredictedJoint, ProposalTrace, StageOutputs, attribute_scene,
                                                 coincident_parts)
    from react3d_core.perception import make_perception
    from react3d_core.pipeline import articulate, load, pack_masks, perceive, view

    cfg = PipelineConfig().with_overrides(config)
    loaded = load(scene_path, cfg.frames)
    scene, mesh, rast = loaded.scene, loaded.mesh, loaded.raster
    if scene.gt_dir is None:
        raise ValueError(f"{scene_path}: no ground truth to attribute against")
    perc = make_perception(scene, cfg.perception)
    res = perceive(perc, scene.frames, cfg.perception)
    masks = pack_masks([res["masks"]])
    trace = SegmentationTrace()
    cands = segment_parts(scene, mesh, masks, perc.point_segmenter, view(cfg, "segmentation"), rasterizer=rast, trace=trace)
    parts = [articulate(loaded, cand, res["predictions"], cfg) for cand in cands]
    valid = [p for p in parts if p is not None]
    kept_ids = {p.candidate_id for p in remove_duplicates(valid, cfg.dedup, mesh.vertices)}
    # every frame once more at the fusion's working size: faces any frame sees, faces under each mask as predicted
    seen: list[np.ndarray] = []
    sets: dict[str, list[np.ndarray]] = {"raw": [], "filled": [], "lifted": []}
    pix: dict[str, list[np.ndarray]] = {"raw": [], "filled": [], "lifted": []}
    for f in scene.frames:
        r = render_work(rast, f, cfg)
        ids = r.face_ids
        seen.append(np.unique(ids))
        for mk in masks.get(f.frame_id, []):
            fm = filled(mk.mask, ids.shape, cfg, r.depth)  # without what is seen through the front, as lifted
            for kind, m in (("raw", resize_mask(mk.mask, ids.shape) & fm), ("filled", fm),
                            ("lifted", prepare_mask(mk.mask, ids.shape, cfg, r.depth))):
                under = ids[m]
                fs, px = np.unique(under[under >= 0], return_counts=True)
                sets[kind].append(fs.astype(np.int64))
                pix[kind].append(px)
    st = StageOutputs(
        view_masks=sets["raw"],
        filled=sets["filled"],
        lifted=sets["lifted"],
        seen=np.setdiff1d(np.unique(np.concatenate(seen)) if seen else np.zeros(0, np.int64), [-1]),
        proposals=[ProposalTrace(np.asarray(p.face_ids, np.int64), o.status, o.reseg_faces, o.kept_faces)
                   for p, o in zip(trace.proposals, trace.outcomes)],
        before_duplicates=[np.asarray(k.face_ids, np.int64) for k in trace.before_duplicates],
        candidates=[np.asarray(k.face_ids, np.int64) for k in cands],
        validated=[p is not None for p in parts],
        kept=[k.candidate_id in kept_ids for k in cands],
        masked_2d=masks_on_parts_2d(scene, masks, cfg),
        face_area=mesh.face_areas,
        view_pixels=pix["raw"], filled_pixels=pix["filled"], lifted_pixels=pix["lifted"],
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
    faces = gt_part_faces(gt)
    boxes = {}
    for pid, f in faces.items():
        f = f[(f >= 0) & (f < mesh.n_faces)]
        if len(f):
            v = mesh.vertices[mesh.faces[f].ravel()]
            boxes[pid] = (v.min(0), v.max(0))
    out = attribute_scene(faces, {p.part_id: p.articulation for p in gt.movable}, rows, preds, st, cfg.evaluation,
                          coincident=coincident_parts(boxes))
    out["stages"] = {"masks": len(st.view_masks), "proposals": len(st.proposals), "candidates": len(cands),
                     "validated": len(valid), "kept": len(kept_ids), "objects": len(manifest.objects)}
    return out
