"""Acceptance on >= 5 synthetic scenes (all procedural kinds + scene-synthesizer): oracle masks with
default realism fuse to parts with vertex-IoU >= 0.5 for >= 90 % of the GT parts seen in >= 3 frames,
with precision >= 0.9 (pooled over scenes; each scene's numbers are printed)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from test_synthetic import run  # noqa: E402

SCENES = [dict(seed=s, kind=k) for s, k in enumerate(("kitchen", "wardrobe", "dresser", "room_door", "mixed"))]


@pytest.mark.slow
def test_oracle_fusion_on_synthetic_scenes(synthetic_scene):
    scenes = [synthetic_scene(n_frames=60, **o) for o in SCENES]
    if importlib.util.find_spec("scene_synthesizer") is not None:
        scenes.append(synthetic_scene(source="scene-synthesizer", seed=0, n_frames=60))
    hit = tot = good = n = 0
    for root in scenes:
        q, cands, _, _ = run(root)
        cols = [q.part_ids.index(p) for p in q.eligible]
        best = q.iou[:, cols].max(0) if len(q.iou) and cols else np.zeros(len(cols))
        hit, tot = hit + int((best >= 0.5).sum()), tot + len(cols)
        good, n = good + int((q.iou.max(1) >= 0.5).sum()) if len(q.iou) else good, n + len(cands)
        print(f"{root.name}: recall {q.recall():.2f} ({len(cols)} parts) precision {q.precision():.2f} ({len(cands)} candidates)")
    assert len(scenes) >= 5 and tot > 0
    assert hit / tot >= 0.9, (hit, tot)
    assert good / max(1, n) >= 0.9, (good, n)
