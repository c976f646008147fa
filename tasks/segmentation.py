"""Scene-level fan-in: all frames' masks -> fused 3D movable-part candidates (react3d_core.fusion)."""

from __future__ import annotations

import time
from typing import Any

from prefect import task

from react3d_core.config import PipelineConfig
from react3d_core.data.masks import PackedMasks

from .keys import content_key
from .perception import get_perception
from .scene import rasterizer, scan_mesh, scene_input
from .store import get, put


def segment_body(scene_path: str, frames_cfg: dict[str, Any], perception: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    from react3d_core.fusion import segment_parts

    t0 = time.perf_counter()
    cfg = PipelineConfig().with_overrides(config)
    scene = scene_input(scene_path, frames_cfg)
    masks = PackedMasks()  # bit-packed: a long capture's masks stay small (issue: memory grew per frame)
    for h in perception:
        for fid, ms in get(h, cache=False)["masks"].items():
            masks.add(fid, ms)
    perc = get_perception(scene, cfg.perception)
    mesh_path = str(scene.mesh_path)
    cands = segment_parts(scene, scan_mesh(mesh_path), masks, perc.point_segmenter, cfg, rasterizer=rasterizer(mesh_path))
    h = put(list(cands), "candidates")
    h["n"] = len(cands)
    h["seconds"] = time.perf_counter() - t0
    return h


@task(name="segment-parts", cache_key_fn=content_key("segmentation", ("react3d_core.fusion",)),
      result_serializer="json", cache_result_in_memory=False)
def segment_scene(scene_path: str, scene_sha: str, frames_cfg: dict[str, Any], perception: list[dict[str, Any]],
                  config: dict[str, Any]) -> dict[str, Any]:
    """Fuse every frame's masks into part candidates with their top-k views (handle, ``n`` candidates)."""
    return segment_body(scene_path, frames_cfg, perception, config)
