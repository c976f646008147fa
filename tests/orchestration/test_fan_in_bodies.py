"""The fan-in task bodies read perception batches economically and give the same result as the core.

Segmentation holds every frame's masks bit-packed; a per-part task opens only the perception batches
that hold its top-k views.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from react3d_core.config import PipelineConfig
from react3d_core.fusion import segment_parts
from tasks.articulation import articulate_body
from tasks.perception import perceive_body
from tasks.scene import fingerprint_body, loaded_scene
from tasks.segmentation import segment_body
from tasks.store import get


def test_fan_in_bodies_match_the_core(synthetic_scene, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    scene_dir = str(synthetic_scene(seed=3, n_frames=16, kind="dresser"))
    cfg = PipelineConfig().with_overrides({"perception": {"backend": "oracle"}, "frames": {"stride": 1}})
    c = cfg.model_dump(mode="json")
    ids = fingerprint_body(scene_dir, c)["frame_ids"]
    perc = [perceive_body(scene_dir, ids[i:i + 8], c) for i in range(0, len(ids), 8)]
    assert len(perc) == 2 and [h["frame_ids"] for h in perc] == [ids[:8], ids[8:]]

    seg = segment_body(scene_dir, perc, c)
    cands = get(seg)
    scene = loaded_scene(scene_dir, c).scene
    masks = {fid: ms for h in perc for fid, ms in get(h)["masks"].items()}
    from tasks.perception import get_perception

    ref = segment_parts(scene, loaded_scene(scene_dir, c).mesh, masks, get_perception(scene, cfg.perception).point_segmenter, cfg)
    assert len(cands) == len(ref) > 0
    for a, b in zip(cands, ref):
        assert np.array_equal(a.face_ids, b.face_ids)
        assert [v.frame_id for v in a.top_views] == [v.frame_id for v in b.top_views]
        assert all(np.array_equal(u.mask.mask, v.mask.mask) for u, v in zip(a.top_views, b.top_views))

    # a batch holding none of the candidate's views is never opened: a handle to a missing file is harmless
    views = {v.frame_id for v in cands[0].top_views}
    gone = {"sha256": "0" * 64, "path": str(tmp_path / "gone.npz"), "kind": "perception",
            "frame_ids": ["not_a_view"]}
    assert "not_a_view" not in views
    h = articulate_body(scene_dir, seg, 0, [*perc, gone], c)
    assert h["kind"] == "articulated-part"
