"""Per-frame-batch perception task around :func:`react3d_core.pipeline.perceive`.

One backend instance per worker process (models load once); batches of frames per task keep Prefect's
per-task overhead small; a GPU out-of-memory error splits the batch in half (``split_on_oom``).
"""

from __future__ import annotations

import threading
import time
from typing import Any

from prefect import task

from react3d_core.config import PerceptionConfig
from react3d_core.data.frames import SceneInput
from react3d_core.perception.interfaces import Perception
from react3d_core.pipeline import perceive, step_config

from .keys import content_key, model_backend_version
from .retry import retry_transient
from .scene import loaded_scene
from .store import put

_BACKENDS: dict[tuple[str, str], Perception] = {}
_BUILD_LOCK = threading.Lock()  # batches run in threads: build a backend once, not once per thread


def get_perception(scene: SceneInput, cfg: PerceptionConfig) -> Perception:
    """The backend for this scene, built once per worker by the perception factory (models, which do not
    depend on the scene: once per worker for all scenes)."""
    from react3d_core.perception import make_perception
    from react3d_core.perception.factory import PLUGIN_BACKENDS

    key = (cfg.model_dump_json(), "" if cfg.backend in PLUGIN_BACKENDS else str(scene.mesh_path))
    with _BUILD_LOCK:
        if key not in _BACKENDS:
            _BACKENDS[key] = make_perception(scene, cfg)
        return _BACKENDS[key]


def perceive_body(scene_path: str, frame_ids: list[str], config: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    scene = loaded_scene(scene_path, config).scene
    cfg = PerceptionConfig.model_validate(config.get("perception", {}))
    by_id = {f.frame_id: f for f in scene.frames}
    result = perceive(get_perception(scene, cfg), [by_id[i] for i in frame_ids], cfg)
    h = put(result, "perception")
    h["seconds"] = time.perf_counter() - t0
    h["n_masks"] = sum(len(m) for m in result["masks"].values())
    h["frame_ids"] = list(frame_ids)  # lets per-part tasks open only the batches holding their views
    return h


@task(name="perceive-frames", cache_key_fn=content_key("perception", extra_versions=model_backend_version),
      retries=2, retry_delay_seconds=[2, 10], retry_condition_fn=retry_transient,
      result_serializer="json", cache_result_in_memory=False)
def perceive_frames(scene_path: str, scene_sha: str, frame_ids: list[str], config: dict[str, Any]) -> dict[str, Any]:
    """Masks and articulation predictions for a batch of frames (a handle into the store)."""
    return perceive_body(scene_path, frame_ids, step_config("perception", config))
