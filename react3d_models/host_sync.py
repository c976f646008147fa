"""Keeping the host from waiting on the GPU: what the H100 profile of the perception stage showed.

With one worker, 32 frames at 1920x1440 took 5.4 s, the GPU busy about a third of it. The host waited:
  * SAM's ViT-H encoder rebuilds its decomposed relative-position tables in every attention layer on every
    call, indexing GPU tables with an index tensor made on the CPU (a host-to-device copy that waits):
    64 waits per batch, 0.73 s of the 5.4 s. The tables depend only on the layer's weights and the
    (fixed) feature size, so :func:`cache_sam_relative_positions` keeps them per layer;
  * Grounding DINO checks an input shape with a GPU reduction whose truth the host reads (``torch_compilable_check``,
    0.30 s); :func:`skip_shape_checks` sets transformers' own switch for it, TRANSFORMERS_DISABLE_TORCH_CHECK=1;
  * worker threads sharing one CUDA stream wait for each other's work at every copy to the host;
    :func:`worker_stream` gives each thread its own stream;
  * SAM's full-resolution boolean masks crossed the bus one byte per pixel into pageable memory (16 masks of a
    1920x1440 frame: 44 MB, 1.0 s of a 5.06 s one-worker run); :func:`masks_to_host` packs 8 pixels per byte
    on the device first, so 1/8 of that crosses, into pinned memory.
(Grounding DINO's post-processing, 13 000 one-element copies per 32 frames, is moved to the CPU in
grounded_sam.detect.)
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import torch

log = logging.getLogger(__name__)

_TABLES_PER_LAYER = 4  # (height, width) tables for at most two feature sizes


def cache_sam_relative_positions(model: Any) -> int:
    """Memoise ``get_rel_pos`` of every SAM vision attention layer of ``model``; returns how many layers.

    A table is reused while the layer's parameter is the same tensor, unchanged (same storage and version),
    and no gradient is wanted; anything else calls the original. Results are identical by construction:
    the cached value is what the original returned for the same arguments."""
    n = 0
    for layer in model.modules():
        if not (hasattr(layer, "get_rel_pos") and hasattr(layer, "rel_pos_h") and callable(layer.get_rel_pos)):
            continue
        if getattr(layer.get_rel_pos, "_react3d_cached", False):
            n += 1
            continue
        layer.get_rel_pos = _cached_rel_pos(layer.get_rel_pos)
        n += 1
    return n


def _cached_rel_pos(original: Any) -> Any:
    cache: dict[tuple[Any, ...], torch.Tensor] = {}
    lock = threading.Lock()

    def get_rel_pos(q_size: int, k_size: int, rel_pos: torch.Tensor) -> torch.Tensor:
        if torch.is_grad_enabled() and rel_pos.requires_grad:
            return original(q_size, k_size, rel_pos)
        key = (int(q_size), int(k_size), rel_pos.data_ptr(), rel_pos._version, rel_pos.dtype, str(rel_pos.device))
        hit = cache.get(key)
        if hit is None:
            hit = original(q_size, k_size, rel_pos)
            if hit.is_cuda:  # another thread may read it from another stream: make it complete first
                torch.cuda.current_stream(hit.device).synchronize()
            with lock:
                if len(cache) >= _TABLES_PER_LAYER:
                    cache.clear()
                cache[key] = hit
        return hit

    get_rel_pos._react3d_cached = True  # type: ignore[attr-defined]
    return get_rel_pos


def skip_shape_checks() -> bool:
    """Turn off transformers' data-dependent input checks (each one a GPU-to-host wait) unless the user set
    TRANSFORMERS_DISABLE_TORCH_CHECK; our inputs come from the models' own processors. True when off."""
    if "TRANSFORMERS_DISABLE_TORCH_CHECK" not in os.environ:
        os.environ["TRANSFORMERS_DISABLE_TORCH_CHECK"] = "1"
        log.info("TRANSFORMERS_DISABLE_TORCH_CHECK=1: input shape checks that wait for the GPU are skipped "
                 "(export TRANSFORMERS_DISABLE_TORCH_CHECK=0 to keep them)")
    return os.environ["TRANSFORMERS_DISABLE_TORCH_CHECK"] == "1"


_LOCAL = threading.local()


@contextmanager
def worker_stream(device: torch.device) -> Iterator[None]:
    """Run the block on this thread's own CUDA stream (nothing on a CPU device).

    The stream first waits for the device's default stream (model weights were loaded there); the block's
    results must be on the host, or their stream synchronised, before another thread reads them."""
    if device.type != "cuda":
        yield
        return
    streams = getattr(_LOCAL, "streams", None)
    if streams is None:
        streams = _LOCAL.streams = {}
    stream = streams.get(device)
    if stream is None:
        stream = streams[device] = torch.cuda.Stream(device)
    if torch.cuda.current_stream(device) == stream:  # nested: already on it
        yield
        return
    stream.wait_stream(torch.cuda.default_stream(device))
    with torch.cuda.stream(stream):
        yield


def pack_bits(m: torch.Tensor) -> torch.Tensor:
    """Pack the last dimension of ``m`` (..., L), 8 elements per uint8 -> (..., ceil(L/8)), on ``m``'s device.

    Same layout as ``np.packbits(..., axis=-1)`` (bit order 'big': the first element is the high bit; the
    last byte is padded with zeros). Non-zero elements count as True. The bit weights are made on the device
    (no host-to-device copy, which would make the host wait for the stream)."""
    length = m.shape[-1]
    x = m.view(torch.uint8) if m.dtype == torch.bool else (m != 0).view(torch.uint8)
    pad = -length % 8
    if pad:
        x = torch.nn.functional.pad(x, (0, pad))
    x = x.reshape(*x.shape[:-1], (length + pad) // 8, 8)
    shifts = torch.arange(7, -1, -1, dtype=torch.uint8, device=x.device)  # weights 128, 64, ..., 1
    return (x << shifts).sum(dim=-1, dtype=torch.uint8)  # distinct bits: the sum is at most 255


def masks_to_host(m: torch.Tensor) -> np.ndarray:
    """Boolean masks (N,H,W) on any device -> a bool numpy array (N,H,W) on the host.

    On a CUDA device only the packed bits cross the bus (:func:`pack_bits`, 1/8 of the bytes), copied into
    pinned memory and unpacked by numpy: the plain ``.cpu()`` of 16 masks of a 1920x1440 frame moved 44 MB
    into pageable memory (about 21 ms each on an H100). On the CPU it is ``m.numpy()`` (no copy for bool)."""
    if m.device.type != "cuda":
        return np.asarray(m.numpy(), dtype=bool)
    n, h, w = m.shape
    if n == 0 or h * w == 0:
        return np.zeros((n, h, w), dtype=bool)
    packed = pack_bits(m.reshape(n, h * w))
    host = torch.empty(packed.shape, dtype=torch.uint8, pin_memory=True)  # torch's caching host allocator
    host.copy_(packed, non_blocking=True)
    torch.cuda.current_stream(m.device).synchronize()  # the copy was queued on this thread's current stream
    return np.unpackbits(host.numpy(), count=h * w, axis=-1).view(bool).reshape(n, h, w)
