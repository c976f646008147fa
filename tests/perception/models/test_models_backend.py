"""make_model_perception end to end on tiny checkpoints: load once, all five calls, clear errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from react3d_core.config import PerceptionConfig
from react3d_core.perception.interfaces import (ArticulationPredictor, PointPromptSegmenter, Tagger, TagFilter,
                                                TextPromptSegmenter)
from react3d_models import STAGE_VERSION, ModelUnavailableError, make_model_perception
from react3d_models.runtime import cached_keys, resolve_device, resolve_dtype
from react3d_models.tagger import select_tags


def _chat(i, body):
    return 200, json.dumps({"choices": [{"message": {"content": '["cabinet", "drawer"]'}}]}).encode(), 0


def _opd(i, body):
    preds = [{"frame_id": f["frame_id"], "joint_type": "revolute", "axis": [0, 1, 0], "origin": [0, 0, 1], "score": 0.9,
              "box": [2, 2, 20, 20]} for f in body["frames"]]
    return 200, json.dumps({"predictions": preds}).encode(), 0


def test_full_backend_on_tiny_models(tiny_models, fake_server, make_frame, make_image):
    chat, opd = fake_server(_chat), fake_server(_opd)
    cfg = PerceptionConfig(backend="models", models=dict(
        detector_model=str(tiny_models["detector"]), sam_model=str(tiny_models["sam"]), tagger_model=str(tiny_models["clip"]),
        tag_filter_endpoint=chat.url + "/v1", articulation_endpoint=opd.url, box_threshold=0.0, text_threshold=0.0,
        batch_size=2, device="cpu"))
    p = make_model_perception(cfg)
    assert p.name == "models" and p.version == STAGE_VERSION
    for obj, proto in [(p.tagger, Tagger), (p.tag_filter, TagFilter), (p.segmenter, TextPromptSegmenter),
                       (p.point_segmenter, PointPromptSegmenter), (p.articulation, ArticulationPredictor)]:
        assert isinstance(obj, proto)
    frames = [make_frame(f"f{i}", 48 + 12 * i, 64 + 16 * i) for i in range(3)]
    images = [make_image(48 + 12 * i, 64 + 16 * i, i) for i in range(3)]
    tags = p.tagger.tag(frames, images)
    assert len(tags) == 3 and all(1 <= len(t) <= 8 for t in tags)
    assert p.tag_filter.filter(["cabinet", "door", "table"]) == ["cabinet", "door"]
    masks = p.segmenter.segment(frames, images, ["cabinet door", "door"])
    assert [m[0].mask.shape for m in masks] == [im.shape[:2] for im in images]
    pm = p.point_segmenter.segment_points(frames[0], images[0], np.array([[30, 20]]), np.array([1]))
    assert pm.mask.shape == (48, 64)
    arts = p.articulation.predict(frames, images)
    assert [len(a) for a in arts] == [1, 1, 1] and arts[2][0].frame_id == "f2"
    assert [len(r["body"]["frames"]) for r in opd.requests] == [2, 1]  # batched by config.models.batch_size
    # loaded once per worker: a second backend reuses the same model objects
    n = len(cached_keys())
    p2 = make_model_perception(cfg)
    assert len(cached_keys()) == n and p2.segmenter.sam is p.segmenter.sam


def test_missing_weights_is_one_clear_line(tmp_path):
    cfg = PerceptionConfig(backend="models", models=dict(detector_model=str(tmp_path / "no-gdino"), device="cpu"))
    with pytest.raises(ModelUnavailableError) as ei:
        make_model_perception(cfg)
    msg = str(ei.value)
    assert "\n" not in msg and "Grounding DINO" in msg and "no-gdino" in msg and "perception.models.detector_model" in msg
    cfg2 = PerceptionConfig(backend="models", models=dict(detector_model="IDEA-Research/grounding-dino-tiny-not-cached", device="cpu"))
    with pytest.raises(ModelUnavailableError, match="HF_HUB_OFFLINE=1.*huggingface-cli download"):
        make_model_perception(cfg2)


def test_device_dtype_and_options():
    cpu = torch.device("cpu")
    assert resolve_device("cpu") == cpu and resolve_dtype("auto", cpu) == torch.float32
    assert resolve_dtype("bf16", cpu) == torch.bfloat16
    if not torch.cuda.is_available():
        assert resolve_device("auto") == cpu


def test_select_tags_hand_computed():
    probs = np.array([[0.5, 0.3, 0.15, 0.05], [0.01, 0.01, 0.9, 0.08]])
    assert select_tags(probs, ["a", "b", "c", "d"], top_k=3, min_prob=0.1) == [["a", "b", "c"], ["c"]]
    assert select_tags(probs, ["a", "b", "c", "d"], top_k=1, min_prob=0.0) == [["a"], ["c"]]


def _benchmark(name: str):  # noqa: ANN202
    """The module benchmarks/<name>.py (a script folder, not a package on the path)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[3] / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_benchmark_runs_tiny(tmp_path):
    """benchmarks/bench_models.py end to end on tiny configs (CPU): table + JSON with the three columns."""
    mod = _benchmark("bench_models")
    out = tmp_path / "b.json"
    assert mod.main(["--tiny", "--images", "2", "--batch", "2", "--rebuild-calls", "1", "--models", "gdino_t,sam_vit_b",
                     "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [r["model"] for r in rows] == ["gdino_t", "sam_vit_b"]
    assert all(r["ours_img_s"] > 0 and r["ref_fp32_b1_img_s"] > 0 and r["ref_rebuild_img_s"] > 0 for r in rows)


def test_mask_transfer_benchmark_flag(tmp_path):
    """bench_models.py --mask-transfer with no models: on the CPU it says it needs CUDA and writes null."""
    mod = _benchmark("bench_models")
    out = tmp_path / "m.json"
    assert mod.main(["--mask-transfer", "--models", "", "--json", str(out)]) == 0
    r = json.loads(out.read_text())
    assert r["rows"] == []
    if torch.cuda.is_available():
        assert r["mask_transfer"]["plain_cpu_numpy_ms"] > 0 and r["mask_transfer"]["masks_to_host_ms"] > 0
    else:
        assert r["mask_transfer"] is None


def test_scene_benchmark_runs_tiny(tmp_path):
    """benchmarks/bench_models_scene.py --quick on tiny models (CPU): the stage over real JPEG files,
    every frame accounted for, masks capped per frame, reference timings present."""
    mod = _benchmark("bench_models_scene")
    out = tmp_path / "s.json"
    assert mod.main(["--tiny", "--quick", "--frames", "4", "--width", "96", "--height", "72", "--batch", "2", "--workers", "2",
                     "--ref-frames", "1", "--max-detections", "3", "--box-threshold", "0.0", "--work", str(tmp_path / "w"),
                     "--json", str(out)]) == 0
    r = json.loads(out.read_text())
    assert r["tiny"] and r["runs"]["ours"]["frames"] == 4 and 0 < r["runs"]["ours"]["masks"] <= 4 * 3
    assert r["ref_fp32_b1_forward_s_per_frame"] > 0 and r["speedup_vs_ref_rebuild"] > 0
    assert set(r["per_call_ms_per_frame"]["batch2"]) >= {"grounding_dino", "sam_encoder", "sam_decoder_masks"}


def test_stage_profiler_runs_tiny(tmp_path):
    """benchmarks/profile_models_stage.py --quick on tiny models (CPU): the base run, the profiler tables
    (ops and Python functions) and no device time without a device."""
    mod = _benchmark("profile_models_stage")
    assert mod.main(["--tiny", "--quick", "--frames", "4", "--profile-frames", "4", "--width", "96", "--height", "72",
                     "--batch", "2", "--workers", "2", "--out", str(tmp_path / "p")]) == 0
    r = json.loads((tmp_path / "p" / "profile.json").read_text())
    assert r["runs"]["base"]["frames"] == 4 and r["profile"]["profiled"]["workers"] == 1
    assert r["profile"]["device_kernel_s"] == 0.0 and r["profile"]["self_cpu_s_all_threads"] > 0
    tables = (tmp_path / "p" / "profile_tables.txt").read_text()
    assert "## by self CPU time" in tables and "## Python (cProfile), one worker" in tables and "perceive" in tables
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "profile.json").write_text("my own")
    with pytest.raises(SystemExit):  # a folder the tool did not make is never written into
        mod.main(["--tiny", "--quick", "--out", str(mine)])
    assert (mine / "profile.json").read_text() == "my own"


def test_local_lm_tag_filter_path(tmp_path):
    """A tiny random Llama through the local-LM path: loads, generates, decodes; its gibberish is
    unreadable, so only 'door' survives (the documented fallback)."""
    import transformers as tf

    from react3d_models.loaders import load_causal_lm
    from react3d_models.tag_filter import CachedTagFilter, local_lm_asker

    words = "[PAD] [UNK] [CLS] [SEP] [MASK] . [ ] , cabinet door drawer table".split()
    torch.manual_seed(0)
    cfg = tf.LlamaConfig(vocab_size=len(words), hidden_size=16, intermediate_size=32, num_hidden_layers=1, num_attention_heads=2,
                         num_key_value_heads=2, max_position_embeddings=512, pad_token_id=0, bos_token_id=2, eos_token_id=3)
    tf.LlamaForCausalLM(cfg).save_pretrained(tmp_path)
    tf.BertTokenizer(vocab={w: i for i, w in enumerate(words)}).save_pretrained(tmp_path)
    lm = load_causal_lm(str(tmp_path), torch.device("cpu"), torch.float32)
    ask = local_lm_asker(lm, max_new_tokens=8)
    reply = ask(["cabinet", "table"])
    assert isinstance(reply, str)
    assert CachedTagFilter(ask, ("door",), retries=0, backoff_s=0).filter(["cabinet", "door", "table"]) == ["door"]
