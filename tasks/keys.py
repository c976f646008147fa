"""Content-based cache keys: what a task computes from, never where files happen to live.

A key hashes the step's identity as the stage descriptors declare it
(:func:`react3d_core.pipeline.key_material`: versions and config sections of the step's stages and
of every stage upstream of them) and the task's other parameters, with handles reduced to their
content hash and path-like parameters dropped.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from typing import Any

from react3d_core.pipeline import key_material

KEY_VERSION = "2"  # 2: keys derived from the stage descriptors


def canonical(x: Any) -> Any:
    """Handles -> their sha256; containers recursively; everything else as JSON sees it."""
    if isinstance(x, dict):
        if "sha256" in x:
            return {"sha256": x["sha256"]}
        return {str(k): canonical(v) for k, v in sorted(x.items(), key=lambda kv: str(kv[0]))}
    if isinstance(x, (list, tuple)):
        return [canonical(v) for v in x]
    return x


ExtraVersions = Callable[[dict[str, Any]], dict[str, str]]
"""Versions of code outside the core that a step's result depends on, given the step's config."""


def model_backend_version(config: dict[str, Any]) -> dict[str, str]:
    """The model backend's version, when the config uses it (its module imports nothing heavy)."""
    if (config.get("perception") or {}).get("backend") != "models":
        return {}
    from react3d_models.version import STAGE_VERSION

    return {"react3d_models": STAGE_VERSION}


def step_key(step: str, params: dict[str, Any], extra_versions: ExtraVersions | None = None,
             ignore: tuple[str, ...] = ("scene_path", "out_dir")) -> str:
    """The cache key of ``step`` called with ``params`` (its ``config`` parameter is the pipeline config,
    of which only the sections the step declares count)."""
    config = params.get("config") or {}
    body = {
        "key_version": KEY_VERSION,
        **key_material(step, config),
        "extra_versions": extra_versions(config) if extra_versions else {},
        "params": {k: canonical(v) for k, v in sorted(params.items()) if k not in ignore and k != "config"},
    }
    return f"{step}-" + hashlib.sha256(json.dumps(body, sort_keys=True, default=str).encode()).hexdigest()[:40]


def content_key(step: str, extra_versions: ExtraVersions | None = None,
                ignore: tuple[str, ...] = ("scene_path", "out_dir")) -> Callable[[Any, dict[str, Any]], str]:
    """A Prefect ``cache_key_fn`` for ``step`` (see :func:`step_key`).

    Defining a cached task also installs the result-record guard: a cache hit is read only from a JSON
    record whose objects verify (``tasks.prefect_env.guard_result_records``)."""
    from .prefect_env import guard_result_records

    guard_result_records()

    def key(_ctx: Any, params: dict[str, Any]) -> str:
        return step_key(step, params, extra_versions, ignore)

    return key
