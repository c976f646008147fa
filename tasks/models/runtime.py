"""Device/dtype choice, the once-per-worker model cache, and the one-line 'weights missing' error.

Models are loaded by hub id or local folder through ``from_pretrained`` and kept in a module-level
cache keyed by (kind, model id, device, dtype): a worker process loads each model once, whatever
number of scenes and batches it serves.
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import torch

from react3d_core.errors import ConfigError

log = logging.getLogger(__name__)

_DTYPES = {"fp32": torch.float32, "float32": torch.float32, "fp16": torch.float16, "float16": torch.float16,
           "bf16": torch.bfloat16, "bfloat16": torch.bfloat16}
_CACHE: dict[tuple[str, str, str, str], Any] = {}
_LOCK = threading.Lock()


class ModelUnavailableError(ConfigError):
    """A model's weights could not be loaded; the message says what to download and where."""


def resolve_device(device: str) -> torch.device:
    """'auto' -> first CUDA GPU when there is one, else CPU."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    dev = torch.device(device)
    if dev.type == "cuda" and not torch.cuda.is_available():
        raise ConfigError(f"perception.device={device!r} but no CUDA GPU is visible; use 'auto' or 'cpu'")
    return dev


def resolve_dtype(dtype: str, device: torch.device) -> torch.dtype:
    """'auto' -> bf16 on GPUs that support it (fp16 otherwise), fp32 on CPU (half is slow there)."""
    if dtype == "auto":
        if device.type != "cuda":
            return torch.float32
        return torch.bfloat16 if torch.cuda.is_bf16_supported() else torch.float16
    if dtype not in _DTYPES:
        raise ConfigError(f"unknown model dtype {dtype!r}; use one of auto, {', '.join(sorted(_DTYPES))}")
    return _DTYPES[dtype]


@dataclass(frozen=True)
class Loaded:
    """A model with its processor, on its device, in its dtype."""

    model: Any
    processor: Any
    device: torch.device
    dtype: torch.dtype


def missing_weights_message(what: str, model_id: str, config_field: str, cause: BaseException) -> str:
    """One line: which model, which hub id / where to put a local copy, which env vars matter."""
    where = "local folder" if Path(model_id).expanduser().exists() else "hub id"
    offline = " (HF_HUB_OFFLINE=1 is set, so nothing is downloaded)" if os.environ.get("HF_HUB_OFFLINE") == "1" else ""
    return (
        f"{what} weights could not be loaded from {where} {model_id!r}{offline}: {type(cause).__name__}: "
        f"{str(cause).splitlines()[0][:200] if str(cause) else ''}. Fix: `huggingface-cli download {model_id}` "
        f"on a machine with internet (cache: $HF_HOME, default ~/.cache/huggingface), or save the model with "
        f"save_pretrained() to a folder and set perception.{config_field} to that path."
    )


def load_cached(kind: str, model_id: str, device: torch.device, dtype: torch.dtype,
                loader: Callable[[str, torch.device, torch.dtype], Loaded], what: str, config_field: str) -> Loaded:
    """Load once per process and key; later calls return the same object."""
    key = (kind, model_id, str(device), str(dtype))
    with _LOCK:
        if key not in _CACHE:
            try:
                _CACHE[key] = loader(model_id, device, dtype)
            except (OSError, ValueError) as exc:
                raise ModelUnavailableError(missing_weights_message(what, model_id, config_field, exc)) from None
            except ImportError as exc:
                first = next((ln.strip() for ln in str(exc).splitlines() if ln.strip()), type(exc).__name__)
                raise ModelUnavailableError(f"{what} {model_id!r} needs a package that is not installed: {first}") from None
            log.info("loaded %s %s on %s (%s)", kind, model_id, device, dtype)
        return _CACHE[key]


def cached_keys() -> list[tuple[str, str, str, str]]:
    """Keys of the models loaded in this process (for tests and manifests)."""
    return list(_CACHE)


def clear_cache() -> None:
    """Forget all loaded models (frees GPU memory when the last reference goes)."""
    with _LOCK:
        _CACHE.clear()


def pretrained(cls: Any, model_id: str, device: torch.device, dtype: torch.dtype) -> Any:
    """``cls.from_pretrained`` in eval mode on ``device``/``dtype`` (no download when HF_HUB_OFFLINE=1)."""
    model = cls.from_pretrained(model_id, dtype=dtype)
    return model.to(device).eval()
