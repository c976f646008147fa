"""Scene-level fan-in around :func:`react3d_core.pipeline.segment`: all frames' masks -> part candidates."""

from __future__ import annotations

import time
from typing import Any

from prefect import task

from react3d_core.config import PerceptionConfig
from react3d_core.pipeline import pack_masks, segment, step_config

from .keys import content_key
from .perception import get_perception
from .scene import loaded_scene
from .store import get, put


def segment_body(scene_path: str, perception: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    loaded = loaded_scene(scene_path, config)
    masks = pack_masks(get(h, cache=False)["masks"] for h in perception)  # each batch decoded once
    perc = get_perception(loaded.scene, PerceptionConfig.model_validate(config.get("perception", {})))
    cands = segment(loaded, masks, perc.point_segmenter, config)
    h = put(list(cands), "candidates")
    h["n"] = len(cands)
    h["seconds"] = time.perf_counter() - t0
    return h


@task(name="segment-parts", cache_key_fn=content_key("segmentation"), result_serializer="json",
      cache_result_in_memory=False)
def segment_scene(scene_path: str, scene_sha: str, perception: list[dict[str, Any]],
                  config: dict[str, Any]) -> dict[str, Any]:
    """Fuse every frame's masks into part candidates with their top-k views (handle, ``n`` candidates)."""
    return segment_body(scene_path, perception, step_config("segmentation", config))
