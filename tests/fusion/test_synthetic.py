"""Fusion with oracle masks on synthetic scenes: vertex-IoU recall/precision, handles, clipping."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from react3d_core.config import PipelineConfig
from react3d_core.data import load_mesh
from react3d_core.fusion import segment_parts
from react3d_core.metrics.segmentation_quality import segmentation_quality
from react3d_core.ground_truth import read_articulate3d
from react3d_core.perception.oracle import OracleModel, make_oracle
from react3d_core.raster import Rasterizer
from react3d_core.scene_io import load_scene


def run(root, overrides: dict | None = None):
    """Oracle masks -> segment_parts -> quality; returns (quality, candidates, gt, model)."""
    cfg = PipelineConfig().with_overrides({"perception": {"backend": "oracle"}, **(overrides or {})})
    scene = load_scene(root)
    mesh = load_mesh(scene.mesh_path)
    perc = make_oracle(scene, cfg.perception)
    model: OracleModel = perc.segmenter.model
    masks = {f.frame_id: model.masks(f) for f in scene.frames}
    seen = Counter(pid for f in scene.frames for pid, _ in model.visible_movable(model.part_image(f)))
    cands = segment_parts(scene, mesh, masks, perc.point_segmenter, cfg, rasterizer=Rasterizer(mesh))
    gt = read_articulate3d(scene.gt_dir)
    return segmentation_quality(cands, gt, seen), cands, gt, model


@pytest.fixture(scope="module")
def dresser(synthetic_scene):
    return synthetic_scene(seed=3, n_frames=16, kind="dresser")


def test_oracle_masks_fuse_to_gt_parts(dresser):
    q, cands, _, _ = run(dresser)
    assert q.eligible
    assert q.recall(0.5) >= 0.9, q.iou.max(0)
    assert q.precision(0.5) >= 0.9, q.iou.max(1)
    for c in cands:
        assert c.top_views and c.top_views[0].iou >= c.top_views[-1].iou > 0.5
        assert c.seg_frame_id == c.top_views[0].frame_id and c.plane_normal is not None


def test_handles_stay_in_the_part_when_masks_miss_them(dresser):
    q, cands, gt, model = run(dresser, {"perception": {"backend": "oracle", "oracle": {"handle_holes": True}}})
    assert q.recall(0.5) >= 0.9
    kept = 0
    for pid, hs in model.handles.items():
        if pid not in q.eligible or not hs or q.best_iou(pid) < 0.5:
            continue
        c = cands[int(np.argmax(q.iou[:, q.part_ids.index(pid)]))]
        hv = np.concatenate([model.parts[h].vert_indices for h in hs])
        assert np.isin(hv, c.vertex_ids).mean() > 0.8, model.parts[pid].label
        kept += 1
    assert kept >= 2


def test_whole_object_masks_are_clipped_to_the_part(dresser):
    over = {"perception": {"backend": "oracle", "oracle": {"whole_object_rate": 1.0, "drop_rate": 0.0}}}
    clipped, *_ = run(dresser, over)
    raw, *_ = run(dresser, {**over, "clip": {"enabled": False}})
    ids = clipped.eligible
    mean = lambda q: np.mean([q.best_iou(p) for p in ids])  # noqa: E731
    assert mean(clipped) > mean(raw) + 0.05, (mean(clipped), mean(raw))
