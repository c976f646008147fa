"""Per-candidate task around :func:`react3d_core.pipeline.articulate`: validate a candidate against the
articulation predictor and refine its joint."""

from __future__ import annotations

import time
from typing import Any

from prefect import task

from react3d_core.pipeline import articulate, step_config
from react3d_core.pipeline.steps import candidate_views

from .keys import content_key
from .scene import loaded_scene
from .store import get, put


def articulate_body(scene_path: str, candidates: dict[str, Any], index: int, perception: list[dict[str, Any]],
                    config: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    loaded = loaded_scene(scene_path, config)
    cand = get(candidates)[index]
    views = candidate_views(cand)
    preds: dict[str, list] = {}
    for h in perception:
        if "frame_ids" in h and views.isdisjoint(h["frame_ids"]):
            continue  # none of this candidate's views: don't decode the batch
        preds.update((fid, p) for fid, p in get(h)["predictions"].items() if fid in views)
    part = articulate(loaded, cand, preds, config)
    h = put(part, "articulated-part") if part is not None else {"sha256": "none", "path": "", "kind": "rejected"}
    h["seconds"] = time.perf_counter() - t0
    return h


@task(name="articulate-part", cache_key_fn=content_key("articulation"), result_serializer="json",
      cache_result_in_memory=False)
def articulate_part(scene_path: str, scene_sha: str, candidates: dict[str, Any], index: int,
                    perception: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    """One candidate -> an articulated part (or a 'rejected' handle when validation fails)."""
    return articulate_body(scene_path, candidates, index, perception, step_config("articulation", config))
