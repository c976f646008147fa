"""Content-based cache keys: what a task computes from, never where files happen to live.

A key hashes the stage name, the stage's ``STAGE_VERSION`` (bumped when its algorithm changes; the
task's own source is not enough because the work happens in ``react3d_core``), and the task's
parameters with handles reduced to their content hash and path-like parameters dropped.
"""

from __future__ import annotations

import hashlib
import importlib
import json
from collections.abc import Callable
from typing import Any

KEY_VERSION = "1"


def stage_version(module: str) -> str:
    """``STAGE_VERSION`` of a react3d_core stage package ("missing" if it is not installed)."""
    try:
        return str(getattr(importlib.import_module(module), "STAGE_VERSION", "0"))
    except ImportError:
        return "missing"


def canonical(x: Any) -> Any:
    """Handles -> their sha256; containers recursively; everything else as JSON sees it."""
    if isinstance(x, dict):
        if "sha256" in x:
            return {"sha256": x["sha256"]}
        return {str(k): canonical(v) for k, v in sorted(x.items(), key=lambda kv: str(kv[0]))}
    if isinstance(x, (list, tuple)):
        return [canonical(v) for v in x]
    return x


def content_key(stage: str, modules: tuple[str, ...], ignore: tuple[str, ...] = ("scene_path", "out_dir")) -> Callable[[Any, dict[str, Any]], str]:
    """A Prefect ``cache_key_fn`` for ``stage`` whose code lives in ``modules``.

    Defining a cached task also installs the result-record guard: a cache hit is read only from a JSON
    record whose objects verify (``tasks.prefect_env.guard_result_records``)."""
    from .prefect_env import guard_result_records

    guard_result_records()

    def key(_ctx: Any, params: dict[str, Any]) -> str:
        body = {
            "stage": stage,
            "key_version": KEY_VERSION,
            "versions": {m: stage_version(m) for m in modules},
            "params": {k: canonical(v) for k, v in sorted(params.items()) if k not in ignore},
        }
        return f"{stage}-" + hashlib.sha256(json.dumps(body, sort_keys=True, default=str).encode()).hexdigest()[:40]

    return key
