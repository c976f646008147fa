"""host_sync: SAM's relative-position tables cached per layer (same embeddings), transformers' input checks
switched off only when the user has not chosen, the per-thread stream a no-op on the CPU, and masks packed
8 pixels per byte before they cross the bus (np.packbits' layout, exact round trip)."""

from __future__ import annotations

import threading

import numpy as np
import pytest
import torch
from transformers import SamModel

from react3d_models.host_sync import (cache_sam_relative_positions, masks_to_host, pack_bits, skip_shape_checks,
                                    worker_stream)
from react3d_models.random_checkpoints import sam_config


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


_MASK_SHAPES = [(3, 37, 53), (0, 5, 5), (1, 1, 1), (2, 8, 8), (4, 3, 7), (16, 48, 64)]


def _random_masks(shape: tuple[int, int, int], seed: int) -> torch.Tensor:
    return torch.rand(shape, generator=torch.Generator().manual_seed(seed)) < 0.4


@pytest.mark.parametrize("shape", _MASK_SHAPES)
def test_pack_bits_is_numpys_packbits_and_round_trips(shape):
    m = _random_masks(shape, sum(shape))
    n, h, w = shape
    flat = m.reshape(n, h * w)
    packed = pack_bits(flat)
    assert packed.dtype == torch.uint8 and packed.shape == (n, (h * w + 7) // 8)
    assert np.array_equal(packed.numpy(), np.packbits(flat.numpy(), axis=-1))  # same bit order, zero padding
    back = np.unpackbits(packed.numpy(), count=h * w, axis=-1).view(bool).reshape(shape)
    assert np.array_equal(back, m.numpy())


def test_pack_bits_counts_non_zero_as_true_and_packs_the_last_axis_of_any_shape():
    x = torch.randint(-2, 3, (2, 3, 11), generator=torch.Generator().manual_seed(3)).float()
    assert np.array_equal(pack_bits(x).numpy(), np.packbits(x.numpy() != 0, axis=-1))
    assert pack_bits(torch.ones(8, dtype=torch.bool)).tolist() == [255]
    assert pack_bits(torch.tensor([True] + [False] * 8)).tolist() == [128, 0]


def test_masks_to_host_on_the_cpu_is_the_tensors_own_memory():
    m = _random_masks((3, 37, 53), 5)
    out = masks_to_host(m)
    assert out.dtype == bool and out.shape == (3, 37, 53) and np.array_equal(out, m.numpy())
    assert np.shares_memory(out, m.numpy())  # no packing, no copy on the CPU
    assert masks_to_host(torch.zeros(0, 4, 6, dtype=torch.bool)).shape == (0, 4, 6)


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
@pytest.mark.parametrize("shape", _MASK_SHAPES + [(16, 1440, 1920)])
def test_masks_to_host_on_cuda_equals_a_plain_copy(shape):
    m = _random_masks(shape, sum(shape)).to("cuda")
    out = masks_to_host(m)
    assert out.dtype == bool and out.shape == shape
    assert np.array_equal(out, m.cpu().numpy())
    flat = m.reshape(shape[0], shape[1] * shape[2])
    assert np.array_equal(pack_bits(flat).cpu().numpy(), np.packbits(flat.cpu().numpy(), axis=-1))


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
def test_masks_to_host_on_a_worker_stream_waits_for_that_stream():
    dev = torch.device("cuda")
    results: dict[int, bool] = {}

    def body(i: int) -> None:
        with worker_stream(dev):
            big = torch.rand((8, 1440, 1920), device=dev, generator=torch.Generator(dev).manual_seed(i))
            m = big < 0.5  # queued on this thread's stream just before the copy
            results[i] = bool(np.array_equal(masks_to_host(m), m.cpu().numpy()))

    threads = [threading.Thread(target=body, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == {0: True, 1: True, 2: True}


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
