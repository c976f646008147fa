"""The models backend on a real synthetic scene's frames (960x720 RGB), tiny checkpoints: slow."""

from __future__ import annotations

import json

import numpy as np
import pytest

from react3d_core.config import PerceptionConfig
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import frame_rgb
from react3d_models import make_model_perception


@pytest.mark.slow
def test_models_backend_on_synthetic_frames(synthetic_scene, tiny_models, fake_server):
    scene = load_scene(synthetic_scene(source="procedural", seed=3, n_frames=6))
    frames = list(scene.frames)[:4]
    images = [frame_rgb(f) for f in frames]
    chat = fake_server(lambda i, body: (200, json.dumps({"choices": [{"message": {"content": '["cabinet"]'}}]}).encode(), 0))
    cfg = PerceptionConfig(backend="models", models=dict(
        detector_model=str(tiny_models["detector"]), sam_model=str(tiny_models["sam"]), tagger_model=str(tiny_models["clip"]),
        tag_filter_endpoint=chat.url, box_threshold=0.0, text_threshold=0.0, batch_size=4, device="cpu"))
    p = make_model_perception(cfg)
    tags = p.tagger.tag(frames, images)
    assert len(tags) == len(frames)
    masks = p.segmenter.segment(frames, images, ["cabinet door", "door"])
    for f, im, ms in zip(frames, images, masks):
        assert ms and all(m.mask.shape == im.shape[:2] and m.frame_id == f.frame_id for m in ms)
    pm = p.point_segmenter.segment_points(frames[0], images[0], np.array([[480, 360]]), np.array([1]))
    assert pm.mask.shape == images[0].shape[:2]
    assert p.articulation.predict(frames, images) == [[] for _ in frames]  # no endpoint configured
