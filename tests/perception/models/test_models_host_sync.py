"""host_sync: SAM's relative-position tables cached per layer (same embeddings), transformers' input checks
switched off only when the user has not chosen, and the per-thread stream a no-op on the CPU."""

from __future__ import annotations

import threading

import pytest
import torch
from transformers import SamModel

from tasks.models.host_sync import cache_sam_relative_positions, skip_shape_checks, worker_stream
from tasks.models.random_checkpoints import sam_config


def _sam() -> SamModel:
    torch.manual_seed(0)
    model = SamModel(sam_config("tiny")).eval()
    with torch.no_grad():  # the tables start at zero: random values everywhere so that a mix-up would show
        for p in model.parameters():
            p.normal_(0.0, 0.3)
    return model


def _count_calls(model: SamModel) -> list[int]:
    """Wrap each layer's current get_rel_pos so calls reaching it are counted (the cache goes on top)."""
    calls = [0]
    for layer in model.modules():
        if hasattr(layer, "rel_pos_h"):
            orig = layer.get_rel_pos

            def counted(q: int, k: int, rel: torch.Tensor, _orig=orig) -> torch.Tensor:
                calls[0] += 1
                return _orig(q, k, rel)

            layer.get_rel_pos = counted
    return calls


def test_cached_relative_positions_give_the_same_embeddings_and_are_computed_once():
    model = _sam()
    x = torch.randn(2, 3, 64, 64, generator=torch.Generator().manual_seed(1))
    with torch.inference_mode():
        plain = model.get_image_embeddings(x)
    calls = _count_calls(model)
    n = cache_sam_relative_positions(model)
    assert n == sum(hasattr(m, "rel_pos_h") for m in model.modules()) >= 1
    assert cache_sam_relative_positions(model) == n  # idempotent: not wrapped twice
    with torch.inference_mode():
        first = model.get_image_embeddings(x)
        after_first = calls[0]
        second = model.get_image_embeddings(x)
    assert torch.equal(first, plain) and torch.equal(second, plain)
    assert after_first == 2 * n  # height and width table of each layer, once
    assert calls[0] == after_first  # the second call computed nothing


def test_a_changed_table_is_not_served_from_the_cache():
    model = _sam()
    cache_sam_relative_positions(model)
    x = torch.randn(1, 3, 64, 64, generator=torch.Generator().manual_seed(2))
    with torch.inference_mode():
        before = model.get_image_embeddings(x)
    with torch.no_grad():
        for layer in model.modules():
            if hasattr(layer, "rel_pos_h"):
                layer.rel_pos_h.mul_(3.0)  # in place: same storage, new version
    with torch.inference_mode():
        after = model.get_image_embeddings(x)
    fresh = _sam()
    with torch.no_grad():
        for layer in fresh.modules():
            if hasattr(layer, "rel_pos_h"):
                layer.rel_pos_h.mul_(3.0)
    with torch.inference_mode():
        expected = fresh.get_image_embeddings(x)
    assert not torch.equal(after, before)
    assert torch.equal(after, expected)


def test_training_bypasses_the_cache():
    model = _sam()
    cache_sam_relative_positions(model)
    layer = next(m for m in model.modules() if hasattr(m, "rel_pos_h"))
    out = layer.get_rel_pos(4, 4, layer.rel_pos_h)
    assert out.requires_grad  # built from the parameter with autograd on: not a cached inference tensor


def test_skip_shape_checks_respects_the_users_choice(monkeypatch):
    monkeypatch.delenv("TRANSFORMERS_DISABLE_TORCH_CHECK", raising=False)
    assert skip_shape_checks() is True
    monkeypatch.setenv("TRANSFORMERS_DISABLE_TORCH_CHECK", "0")
    assert skip_shape_checks() is False
    import os

    assert os.environ["TRANSFORMERS_DISABLE_TORCH_CHECK"] == "0"


def test_worker_stream_is_a_no_op_on_the_cpu():
    seen: list[bool] = []

    def body() -> None:
        with worker_stream(torch.device("cpu")):
            seen.append(torch.ones(2).sum().item() == 2.0)

    threads = [threading.Thread(target=body) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert seen == [True, True, True]


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
def test_worker_stream_gives_each_thread_its_own_stream():
    dev = torch.device("cuda")
    streams: dict[str, torch.cuda.Stream] = {}

    def body(name: str) -> None:
        with worker_stream(dev):
            streams[name] = torch.cuda.current_stream(dev)
            with worker_stream(dev):  # nested: the same stream
                assert torch.cuda.current_stream(dev) == streams[name]

    threads = [threading.Thread(target=body, args=(f"t{i}",)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert streams["t0"] != streams["t1"]
    assert all(s != torch.cuda.default_stream(dev) for s in streams.values())
