"""``perception.models`` from a ``--config`` JSON file reaches the built backend (tiny random models on the
CPU): dtype, vocabulary, detection cap, NMS, batch sizes, endpoint timeouts/retries and reply lengths."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest
import torch

from react3d_core.config import PipelineConfig
from react3d_core.data.frames import SceneInput
from react3d_core.errors import ConfigError

VOCAB = ["kitchen drawer", "oven door", "floor"]


def _chat(i, body):
    return 200, json.dumps({"choices": [{"message": {"content": '["oven"]'}}]}).encode(), 0


def _opd(i, body):
    preds = [{"frame_id": f["frame_id"], "joint_type": "prismatic", "axis": [0, 0, 1], "origin": [0, 0, 1],
              "score": 0.9, "box": [2, 2, 20, 20]} for f in body["frames"]]
    return 200, json.dumps({"predictions": preds}).encode(), 0


def _scene(tmp_path: Path, frames: list) -> SceneInput:
    return SceneInput(scene_id="s", root=tmp_path, mesh_path=tmp_path / "mesh.ply", frames=tuple(frames),
                      source_format="synthetic")


def _cli_config(path: Path) -> PipelineConfig:
    """What ``react3d convert SCENE --perception models --config PATH`` validates and hands to the flow."""
    from flows.commands._runconfig import pipeline_overrides

    args = argparse.Namespace(config=str(path), perception="models", no_refine=False, stride=None, max_frames=None,
                              formats=None)
    return PipelineConfig().with_overrides(pipeline_overrides(args))


def test_models_section_from_a_config_file_reaches_the_backend(tiny_models, fake_server, make_frame, make_image,
                                                               tmp_path):
    chat, opd = fake_server(_chat), fake_server(_opd)
    section = {"device": "cpu", "dtype": "bf16", "batch_size": 2,
               "detector_model": str(tiny_models["detector"]), "sam_model": str(tiny_models["sam"]),
               "tagger_model": "xinyu1205/recognize-anything-plus-model", "clip_model": str(tiny_models["clip"]),
               "box_threshold": 0.0, "text_threshold": 0.0,
               "nms_iou": 0.5, "max_detections": 2, "gpu_preprocess": False,
               "tag_vocabulary": VOCAB, "tag_top_k": 2, "tag_min_prob": 0.0,
               "tag_filter_endpoint": chat.url + "/v1", "tag_filter_model": "my-llm", "llm_timeout_s": 5.0,
               "llm_retries": 1, "llm_backoff_s": 0.0, "llm_endpoint_max_tokens": 64, "llm_max_new_tokens": 16,
               "articulation_endpoint": opd.url, "articulation_timeout_s": 7.0, "articulation_retries": 0,
               "articulation_backoff_s": 0.0, "articulation_min_score": 0.95}
    path = tmp_path / "gpu.json"
    path.write_text(json.dumps({"perception": {"batch_size": 3, "models": section}}))
    cfg = _cli_config(path)
    assert cfg.perception.backend == "models" and cfg.perception.models.model_dump(mode="json") == section
    assert set(section) == set(type(cfg.perception.models).model_fields)  # every field of the section is set here
    assert PipelineConfig.from_file(path).perception.models == cfg.perception.models

    # the task's entry point: the core factory, which imports react3d_models on demand
    from tasks.perception import get_perception

    frames = [make_frame(f"f{i}", 48 + 12 * i, 64 + 16 * i) for i in range(3)]
    images = [make_image(48 + 12 * i, 64 + 16 * i, i) for i in range(3)]
    p = get_perception(_scene(tmp_path, frames), cfg.perception)
    assert p.name == "models"
    seg, tagger = p.segmenter, p.tagger
    for loaded in (seg.detector, seg.sam, tagger.clip):
        assert loaded.dtype == torch.bfloat16 and next(loaded.model.parameters()).dtype == torch.bfloat16
        assert loaded.device.type == "cpu"
    assert (seg.max_detections, seg.nms_iou, seg.box_threshold, seg.text_threshold) == (2, 0.5, 0.0, 0.0)
    assert seg.batch_size == tagger.batch_size == p.articulation.batch_size == 2
    assert not seg.gpu_preprocess and not tagger.gpu_preprocess
    assert tagger.vocabulary == VOCAB and (tagger.top_k, tagger.min_prob) == (2, 0.0)
    assert tagger.clip.model.name_or_path == str(tiny_models["clip"])  # the RAM++ id selects clip_model
    art = p.articulation
    assert (art.timeout_s, art.retries, art.backoff_s, art.min_score) == (7.0, 0, 0.0, 0.95)

    # and they act: tags from the custom vocabulary only, at most 2 masks a frame, the chat reply length
    tags = tagger.tag(frames, images)
    assert len(tags) == 3 and all(1 <= len(t) <= 2 and set(t) <= set(VOCAB) for t in tags)
    masks = seg.segment(frames, images, ["oven door", "door"])
    assert [m[0].mask.shape for m in masks] == [im.shape[:2] for im in images]
    assert all(len(m) <= 2 for m in masks) and any(len(m) == 2 for m in masks)  # thresholds 0: hundreds of boxes
    assert p.tag_filter.filter(["oven", "table", "door"]) == ["door", "oven"]
    assert chat.requests[0]["body"]["max_tokens"] == 64 and chat.requests[0]["body"]["model"] == "my-llm"
    assert p.articulation.predict(frames, images) == [[], [], []]  # score 0.9 < min_score 0.95
    assert [len(r["body"]["frames"]) for r in opd.requests] == [2, 1]


def test_local_tag_filter_reply_length(tiny_models, make_frame, tmp_path):
    """Without an endpoint the tag filter is the local language model named by tag_filter_model, and
    llm_max_new_tokens bounds its reply (a tiny random Llama, word-level tokenizer: one word per token)."""
    import transformers as tf

    from react3d_core.perception import make_perception

    words = "[PAD] [UNK] [CLS] [SEP] [MASK] . [ ] , cabinet door drawer table".split()
    torch.manual_seed(0)
    lm_cfg = tf.LlamaConfig(vocab_size=len(words), hidden_size=16, intermediate_size=32, num_hidden_layers=1,
                            num_attention_heads=2, num_key_value_heads=2, max_position_embeddings=512, pad_token_id=0,
                            bos_token_id=2, eos_token_id=3)
    tf.LlamaForCausalLM(lm_cfg).save_pretrained(tmp_path / "lm")
    tf.BertTokenizer(vocab={w: i for i, w in enumerate(words)}).save_pretrained(tmp_path / "lm")
    replies = {}
    for n in (8, 40):
        cfg = PipelineConfig().with_overrides({"perception": {"backend": "models", "models": {
            "device": "cpu", "detector_model": str(tiny_models["detector"]), "sam_model": str(tiny_models["sam"]),
            "tagger_model": str(tiny_models["clip"]), "tag_filter_model": str(tmp_path / "lm"), "llm_max_new_tokens": n}}})
        p = make_perception(_scene(tmp_path, [make_frame("f0", 48, 64)]), cfg.perception)
        replies[n] = p.tag_filter.ask(["cabinet", "table"]).split()
    assert 1 <= len(replies[8]) <= 8 < len(replies[40]) <= 40
    assert replies[40][:len(replies[8])] == replies[8]  # greedy: the longer reply continues the shorter one


def test_defaults_are_the_papers_and_fp32_on_the_cpu(tiny_models, fake_server, make_frame, tmp_path):
    """Only the weights named: thresholds 0.3/0.25, 100 boxes, NMS 0.8, the built-in vocabulary, fp32 on the CPU."""
    from react3d_core.config import ModelsConfig
    from react3d_core.config.models import DEFAULT_VOCABULARY
    from react3d_core.perception import make_perception

    chat = fake_server(_chat)
    cfg = PipelineConfig().with_overrides({"perception": {"backend": "models", "models": {
        "device": "cpu", "detector_model": str(tiny_models["detector"]), "sam_model": str(tiny_models["sam"]),
        "tagger_model": str(tiny_models["clip"]), "tag_filter_endpoint": chat.url}}})
    p = make_perception(_scene(tmp_path, [make_frame("f0", 48, 64)]), cfg.perception)
    seg = p.segmenter
    assert (seg.box_threshold, seg.text_threshold, seg.max_detections, seg.nms_iou) == (0.3, 0.25, 100, 0.8)
    assert seg.sam.dtype == torch.float32 and seg.batch_size == ModelsConfig().batch_size == 8
    assert tuple(p.tagger.vocabulary) == DEFAULT_VOCABULARY and p.tagger.top_k == 8


@pytest.mark.parametrize("models, field", [
    ({"dtype": "fp8"}, "perception.models.dtype"),
    ({"device": "gpu"}, "perception.models.device"),
    ({"max_detections": 0}, "perception.models.max_detections"),
    ({"tag_vocabulary": []}, "perception.models.tag_vocabulary"),
    ({"tag_vocabulary": ["oven", "Oven"]}, "perception.models.tag_vocabulary"),
    ({"clip_modle": "x"}, "perception.models.clip_modle"),
])
def test_bad_values_in_a_config_file_are_one_line(tmp_path, models, field):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"perception": {"backend": "models", "models": models}}))
    with pytest.raises(ConfigError) as e:
        _cli_config(path)
    msg = str(e.value)
    assert "\n" not in msg and field in msg
    with pytest.raises(ConfigError) as e2:
        PipelineConfig.from_file(path)
    assert str(e2.value).startswith(f"{path}: invalid config: ") and field in str(e2.value) and "\n" not in str(e2.value)


def test_cuda_device_without_a_gpu_names_the_field():
    """'cuda' on a machine without a GPU is a one-line ConfigError naming the section's field."""
    from react3d_models.runtime import resolve_device

    if torch.cuda.is_available():
        pytest.skip("a CUDA device is visible")
    with pytest.raises(ConfigError, match=r"^perception\.models\.device='cuda' but no CUDA GPU is visible"):
        resolve_device("cuda")


def test_missing_clip_weights_name_the_field_to_change(tiny_models, tmp_path):
    """With the RAM++ id as tagger (the default), the CLIP weights come from clip_model, and the error says so."""
    from react3d_models import ModelUnavailableError, make_model_perception

    cfg = PipelineConfig().with_overrides({"perception": {"backend": "models", "models": {
        "device": "cpu", "detector_model": str(tiny_models["detector"]), "sam_model": str(tiny_models["sam"]),
        "clip_model": str(tmp_path / "no-clip"), "tag_filter_endpoint": "http://127.0.0.1:9/v1"}}})
    with pytest.raises(ModelUnavailableError, match=r"CLIP tagger '.*no-clip' \(perception\.models\.clip_model\)") as e:
        make_model_perception(cfg.perception)
    assert "\n" not in str(e.value)
