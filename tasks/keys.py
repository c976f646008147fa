"""Content-based cache keys: what a task computes from, never where files happen to live.

A key hashes the step's identity as the stage descriptors declare it
(:func:`react3d_core.pipeline.key_material`: versions and config sections of the step's stages and
of every stage upstream of them) and the task's other parameters, with handles reduced to their
content hash and path-like parameters dropped.
"""

from __future__ import annotations

import hashlib
import importlib
import json
from collections.abc import Callable
from typing import Any

from react3d_core.pipeline import key_material

KEY_VERSION = "2"  # 2: keys derived from the stage descriptors (issue #17)


def stage_version(module: str) -> str:
    """``STAGE_VERSION`` of a module outside the core stages (e.g. ``tasks.models``); "missing" if absent."""
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


def step_key(step: str, params: dict[str, Any], extra_versions: tuple[str, ...] = (),
             ignore: tuple[str, ...] = ("scene_path", "out_dir")) -> str:
    """The cache key of ``step`` called with ``params`` (its ``config`` parameter is the pipeline config,
    of which only the sections the step declares count)."""
    body = {
        "key_version": KEY_VERSION,
        **key_material(step, params.get("config") or {}),
        "extra_versions": {m: stage_version(m) for m in extra_versions},
        "params": {k: canonical(v) for k, v in sorted(params.items()) if k not in ignore and k != "config"},
    }
    return f"{step}-" + hashlib.sha256(json.dumps(body, sort_keys=True, default=str).encode()).hexdigest()[:40]


def content_key(step: str, extra_versions: tuple[str, ...] = (),
                ignore: tuple[str, ...] = ("scene_path", "out_dir")) -> Callable[[Any, dict[str, Any]], str]:
    """A Prefect ``cache_key_fn`` for ``step`` (see :func:`step_key`).

    Defining a cached task also installs the result-record guard: a cache hit is read only from a JSON
    record whose objects verify (``tasks.prefect_env.guard_result_records``)."""
    from .prefect_env import guard_result_records

    guard_result_records()

    def key(_ctx: Any, params: dict[str, Any]) -> str:
        return step_key(step, params, extra_versions, ignore)

    return key
