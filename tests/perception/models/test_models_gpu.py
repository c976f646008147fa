"""The model backend on a CUDA device: bf16 loading, pre-processing and mask upsampling on the GPU,
and the out-of-memory split with a real CUDA out-of-memory error. Run with ``pytest -m gpu``."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from react3d_core.config import PerceptionConfig
from react3d_core.pipeline.steps import split_on_oom
from react3d_models import make_model_perception
from react3d_models.grounded_sam import masks_to_original
from react3d_models.runtime import preprocess

pytestmark = [pytest.mark.gpu, pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")]


def _cfg(tiny_models, fake_server) -> PerceptionConfig:
    chat = fake_server(lambda i, body: (200, b'{"choices": [{"message": {"content": "[\\"cabinet\\"]"}}]}', 0))
    return PerceptionConfig(backend="models", models=dict(
        detector_model=str(tiny_models["detector"]), sam_model=str(tiny_models["sam"]), tagger_model=str(tiny_models["clip"]),
        tag_filter_endpoint=chat.url + "/v1", box_threshold=0.0, text_threshold=0.0, batch_size=2, device="cuda"))


def test_backend_loads_bf16_on_cuda_and_returns_frame_size_masks(tiny_models, fake_server, make_frame, make_image):
    p = make_model_perception(_cfg(tiny_models, fake_server))
    seg = p.segmenter
    assert seg.sam.device.type == "cuda" and seg.sam.dtype == torch.bfloat16
    assert next(seg.sam.model.parameters()).dtype == torch.bfloat16
    frames = [make_frame(f"f{i}", 120, 160) for i in range(3)]
    images = [make_image(120, 160, i) for i in range(3)]
    masks = seg.segment(frames, images, ["cabinet door", "door"])
    assert len(masks) == 3 and all(m.mask.shape == (120, 160) and m.mask.dtype == bool for ms in masks for m in ms)
    assert any(masks)
    assert len(p.tagger.tag(frames, images)) == 3


def test_gpu_preprocessing_matches_the_cpu(tiny_models, make_image):
    from transformers import AutoProcessor

    proc = AutoProcessor.from_pretrained(str(tiny_models["sam"]))
    if type(proc.image_processor).__name__.endswith("Pil"):
        pytest.skip("this transformers has no torch image backend (torchvision missing): processors run on the CPU")
    images = [make_image(120, 160, i) for i in range(2)]
    cpu = preprocess(proc, torch.device("cpu"), images=images)
    gpu = preprocess(proc, torch.device("cuda"), images=images)
    assert gpu["pixel_values"].shape == cpu["pixel_values"].shape
    diff = (gpu["pixel_values"].float().cpu() - cpu["pixel_values"].float()).abs()
    assert float(diff.mean()) < 0.02, float(diff.mean())  # normalised units: same resize, another device


def test_mask_upsampling_on_gpu_matches_the_cpu(tiny_models, fake_server):
    p = make_model_perception(_cfg(tiny_models, fake_server))
    sam = p.segmenter.sam
    low = torch.randn(1, 5, 1, 32, 32, generator=torch.Generator().manual_seed(0))
    on_cpu = masks_to_original(sam, low, (120, 160), (48, 64))
    on_gpu = masks_to_original(sam, low.to("cuda"), (120, 160), (48, 64))
    assert on_gpu.shape == on_cpu.shape == (5, 120, 160)
    assert (on_gpu == on_cpu).mean() > 0.999


def test_split_on_oom_halves_a_batch_after_a_real_cuda_oom():
    """Each frame needs 1 GiB; under a ~3.5 GiB cap a batch of 8 fails, and so does 4, while 2 fits."""
    torch.cuda.empty_cache()
    total = torch.cuda.get_device_properties(0).total_memory
    base = torch.cuda.memory_allocated()
    attempts: list[tuple[int, bool]] = []

    def fn(frames: list[int], images: list[int]) -> list[int]:
        try:
            x = torch.ones(len(frames), 2**28, device="cuda")  # 1 GiB per frame in fp32
        except torch.cuda.OutOfMemoryError:
            attempts.append((len(frames), False))
            raise
        attempts.append((len(frames), True))
        return [int(v) * f for v, f in zip(x[:, 0].tolist(), frames)]

    torch.cuda.set_per_process_memory_fraction(min(1.0, (base + 3.5 * 2**30) / total))
    try:
        out = split_on_oom(fn, list(range(8)), list(range(8)))
    finally:
        torch.cuda.set_per_process_memory_fraction(1.0)
        torch.cuda.empty_cache()
    assert out == list(range(8))
    assert attempts[:3] == [(8, False), (4, False), (2, True)]
    assert all(ok for n, ok in attempts if n <= 2) and sum(n for n, ok in attempts if ok) == 8


def test_split_on_oom_still_raises_other_errors():
    def fn(frames: list[int], images: list[int]) -> list[int]:
        raise ValueError("not memory")

    with pytest.raises(ValueError, match="not memory"):
        split_on_oom(fn, [1, 2], [1, 2])


def test_tiny_bench_runs_on_the_gpu(tmp_path):
    """The scene benchmark end to end on the GPU with tiny models (the real-size run is the benchmark)."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    out = tmp_path / "b.json"
    subprocess.run([sys.executable, str(root / "benchmarks/bench_models_scene.py"), "--tiny", "--frames", "12", "--width", "320",
                    "--height", "240", "--batch", "4", "--subset", "8", "--ref-frames", "1", "--json", str(out)],
                   check=True, cwd=root, timeout=300)
    r = json.loads(out.read_text())
    assert r["device"] != "cpu" and r["runs"]["ours"]["frames"] == 12
    assert r["oom_split"]["returned_frames"] == 8
    assert np.isfinite(r["speedup_vs_ref_forward"])


def test_threads_on_their_own_streams_give_the_sequential_masks(tiny_models, fake_server, make_frame, make_image):
    """Four worker threads, each on its own CUDA stream (host_sync.worker_stream), against one thread."""
    from concurrent.futures import ThreadPoolExecutor

    seg = make_model_perception(_cfg(tiny_models, fake_server)).segmenter
    frames = [make_frame(f"f{i}", 120, 160) for i in range(8)]
    images = [make_image(120, 160, i) for i in range(8)]
    phrases = ["cabinet door", "door"]
    ref = seg.segment(frames, images, phrases)
    with ThreadPoolExecutor(4) as ex:
        got = [m for part in ex.map(lambda s: seg.segment(frames[s : s + 2], images[s : s + 2], phrases), range(0, 8, 2))
               for m in part]
    assert [len(m) for m in got] == [len(m) for m in ref] and any(ref)
    for a, b in zip(got, ref):
        for x, y in zip(a, b):
            assert x.box == pytest.approx(y.box) and (x.mask == y.mask).mean() > 0.999
