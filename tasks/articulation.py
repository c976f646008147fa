"""Per-candidate task: validate a candidate against the articulation predictor and refine its joint."""

from __future__ import annotations

import time
from typing import Any

from prefect import task

from react3d_core.config import PipelineConfig

from .keys import content_key
from .scene import rasterizer, scan_mesh, scene_input
from .store import get, put


def articulate_body(scene_path: str, frames_cfg: dict[str, Any], candidates: dict[str, Any], index: int,
                    perception: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    from react3d_core.articulation import articulate_candidate

    t0 = time.perf_counter()
    cfg = PipelineConfig().with_overrides(config)
    scene = scene_input(scene_path, frames_cfg)
    cand = get(candidates)[index]
    views = {v.frame_id for v in cand.top_views}
    preds: dict[str, list] = {}
    for h in perception:
        if "frame_ids" in h and views.isdisjoint(h["frame_ids"]):
            continue  # none of this candidate's views: don't decode the batch
        for fid, p in get(h)["predictions"].items():
            if fid in views:
                preds[fid] = p
    mesh_path = str(scene.mesh_path)
    part = articulate_candidate(scene, scan_mesh(mesh_path), cand, preds, cfg, rasterizer=rasterizer(mesh_path))
    h = put(part, "articulated-part") if part is not None else {"sha256": "none", "path": "", "kind": "rejected"}
    h["seconds"] = time.perf_counter() - t0
    return h


@task(name="articulate-part", cache_key_fn=content_key("articulation", ("react3d_core.articulation",)),
      result_serializer="json", cache_result_in_memory=False)
def articulate_part(scene_path: str, scene_sha: str, frames_cfg: dict[str, Any], candidates: dict[str, Any], index: int,
                    perception: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    """One candidate -> an articulated part (or a 'rejected' handle when validation fails)."""
    return articulate_body(scene_path, frames_cfg, candidates, index, perception, config)
