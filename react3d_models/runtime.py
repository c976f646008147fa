"""Device/dtype choice, the once-per-worker model cache, and the one-line 'weights missing' error.

Models are loaded by hub id or local folder through ``from_pretrained`` and kept in a module-level
cache keyed by (kind, model id, device, dtype): a worker process loads each model once, whatever
number of scenes and batches it serves.
"""

from __future__ import annotations

import logging
import os
import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import torch

from react3d_core.errors import ConfigError

log = logging.getLogger(__name__)

SECTION = "perception.models"  # where the settings named in error messages live

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
        raise ConfigError(f"{SECTION}.device={device!r} but no CUDA GPU is visible; use 'auto' or 'cpu'")
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
        f"save_pretrained() to a folder and set {SECTION}.{config_field} to that path."
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
    """``cls.from_pretrained`` in eval mode on ``device``/``dtype`` (no hub request for a local copy)."""
    model = cls.from_pretrained(model_id, dtype=dtype, **hub_kwargs(model_id))
    return model.to(device).eval()


# --- moving inputs to the model ----------------------------------------------------------------------
#
# A 1920x1440 frame resized and normalised by a processor on the CPU costs tens of milliseconds per model;
# processors with a torch (torchvision) backend do the same on the GPU when given ``device``. PIL-backend
# processors (no torchvision installed) and CPU runs keep the CPU path; a processor that refuses the
# keyword is remembered and not asked again.

_NO_DEVICE_KWARG: weakref.WeakSet[Any] = weakref.WeakSet()  # processors that refused it (not their ids: ids are reused)


def _accepts_device(processor: Any) -> bool:
    ip = getattr(processor, "image_processor", processor)
    return not type(ip).__name__.endswith("Pil") and processor not in _NO_DEVICE_KWARG


def preprocess(processor: Any, device: torch.device, on_device: bool = True, **kwargs: Any) -> dict[str, Any]:
    """``processor(**kwargs, return_tensors="pt")``, run on ``device`` when it is a GPU, ``on_device`` is set
    and the processor's image backend is torch; otherwise on the CPU (the result is moved by :func:`to_model`)."""
    if on_device and device.type == "cuda" and _accepts_device(processor):
        try:
            return dict(processor(**kwargs, return_tensors="pt", device=str(device)))
        except Exception as exc:  # noqa: BLE001 - no device keyword in this version; a real input error recurs below
            log.info("%s does not pre-process on %s (%s); using the CPU", type(processor).__name__, device, exc)
            _NO_DEVICE_KWARG.add(processor)
    return dict(processor(**kwargs, return_tensors="pt"))


def to_model(inputs: dict[str, Any], device: torch.device, dtype: torch.dtype) -> dict[str, Any]:
    """Tensors onto the model's device (floats in its dtype); CPU tensors go through pinned memory so the
    copy does not block the host thread."""
    out: dict[str, Any] = {}
    for k, v in inputs.items():
        if not isinstance(v, torch.Tensor):
            out[k] = v
            continue
        if device.type == "cuda" and v.device.type == "cpu":
            v = v.pin_memory()
        out[k] = v.to(device, dtype, non_blocking=True) if v.is_floating_point() else v.to(device, non_blocking=True)
    return out


# --- offline first: know what is on this machine before anything talks to the hub --------------------
#
# Without weights, ``from_pretrained`` on a closed network retried the hub for minutes (197 s and 238 log
# lines before the clear message). Every model the backend needs is now looked up locally first (a
# folder, or the Hugging Face cache); only what is missing may be downloaded, and only from a hub that
# answers a single short probe. Otherwise one line names every missing model and how to get it.

HUB_PROBE_TIMEOUT_S = 3.0


@dataclass(frozen=True)
class ModelNeed:
    """One model the backend will load: what it is, its hub id or folder, and the field of perception.models naming it."""

    what: str
    model_id: str
    config_field: str


def _looks_like_path(model_id: str) -> bool:
    return model_id.startswith(("/", ".", "~")) or model_id.count("/") > 1 or os.sep == "\\" and "\\" in model_id


def locally_available(model_id: str) -> bool:
    """True when ``model_id`` is a folder here, or a hub id whose config is in the Hugging Face cache."""
    path = Path(model_id).expanduser()
    if path.exists() or _looks_like_path(model_id):
        return path.is_dir()
    try:
        from huggingface_hub import try_to_load_from_cache

        return isinstance(try_to_load_from_cache(model_id, "config.json"), str)
    except Exception:  # noqa: BLE001 - an invalid repo id is simply not available
        return False


def hub_kwargs(model_id: str) -> dict[str, Any]:
    """``from_pretrained`` keywords: a model found locally is read with ``local_files_only`` (no hub requests)."""
    return {"local_files_only": True} if locally_available(model_id) else {}


def hub_offline() -> bool:
    """HF_HUB_OFFLINE (or TRANSFORMERS_OFFLINE) is set to a true value."""
    return any(os.environ.get(k, "").strip().upper() in ("1", "ON", "YES", "TRUE")
               for k in ("HF_HUB_OFFLINE", "TRANSFORMERS_OFFLINE"))


def hub_endpoint() -> str:
    return os.environ.get("HF_ENDPOINT", "").rstrip("/") or "https://huggingface.co"


def hub_reachable(timeout: float = HUB_PROBE_TIMEOUT_S) -> bool:
    """One HTTP request to the hub endpoint, no retries: any HTTP answer within ``timeout`` counts."""
    import urllib.error
    import urllib.request

    answered: list[bool] = []

    def probe() -> None:
        try:
            urllib.request.urlopen(urllib.request.Request(hub_endpoint() + "/api/whoami-v2", method="HEAD"),
                                   timeout=timeout).close()
            answered.append(True)
        except urllib.error.HTTPError:
            answered.append(True)  # 401/404: the hub is there
        except Exception:  # noqa: BLE001 - unreachable, refused, DNS, TLS: not reachable
            answered.append(False)

    t = threading.Thread(target=probe, daemon=True)  # DNS resolution has no timeout of its own
    t.start()
    t.join(timeout + 1.0)
    return bool(answered and answered[0])


def check_models_available(needs: list[ModelNeed]) -> None:
    """Fail in seconds, with one line naming every missing model, when the weights are neither here nor
    downloadable now (HF_HUB_OFFLINE set, or the hub does not answer a single short probe)."""
    missing = [n for n in needs if not locally_available(n.model_id)]
    if not missing:
        return
    if any(_looks_like_path(n.model_id) or Path(n.model_id).expanduser().exists() for n in missing):
        why = "a configured local folder does not exist" + (", and HF_HUB_OFFLINE=1 is set" if hub_offline() else "")
    elif hub_offline():
        why = "HF_HUB_OFFLINE=1 is set, so nothing is downloaded"
    elif not hub_reachable():
        why = f"the model hub {hub_endpoint()} did not answer within {HUB_PROBE_TIMEOUT_S:.0f} s"
    else:
        log.warning("downloading %s from %s", ", ".join(n.model_id for n in missing), hub_endpoint())
        return
    names = "; ".join(f"{n.what} {n.model_id!r} ({SECTION}.{n.config_field})" for n in missing)
    ids = " ".join(n.model_id for n in missing if not _looks_like_path(n.model_id))
    raise ModelUnavailableError(
        f"model weights not available on this machine ({why}): {names}. Fix: "
        + (f"`huggingface-cli download {ids}` (each id) on a machine with internet and copy the cache "
           f"($HF_HOME, default ~/.cache/huggingface), or " if ids else "")
        + f"save each model with save_pretrained() to a folder and set the {SECTION} field to that path.")


def api_key(env_vars: tuple[str, ...], secret_block_var: str) -> str | None:
    """An endpoint's key: the first of ``env_vars`` that is set, else the Prefect Secret block named by
    ``$secret_block_var``. Never from the config: endpoints are recorded in scene.json and run parameters."""
    for var in env_vars:
        if os.environ.get(var):
            return os.environ[var]
    block = os.environ.get(secret_block_var)
    if not block:
        return None
    try:
        from prefect.blocks.system import Secret

        return str(Secret.load(block).get())
    except Exception as exc:  # noqa: BLE001 - one line, whatever the server said
        raise ConfigError(f"{secret_block_var}={block!r}: the Prefect Secret block could not be read "
                          f"({type(exc).__name__}); create it with `prefect block create secret` or unset the variable") from None

