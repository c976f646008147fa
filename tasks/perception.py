"""Per-frame-batch perception task: tags -> openable phrases -> 2D masks, and articulation predictions.

One backend instance per worker process (models load once); batches of frames per task keep Prefect's
per-task overhead small; a GPU out-of-memory error splits the batch in half and retries the halves.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from prefect import task

from react3d_core.config import PerceptionConfig
from react3d_core.data.frames import SceneInput
from react3d_core.perception.interfaces import Perception
from react3d_core.scene_io.images import frame_rgb

from .keys import content_key
from .retry import retry_transient
from .scene import scene_input
from .store import put

T = TypeVar("T")
_BACKENDS: dict[tuple[str, str], Perception] = {}
_BUILD_LOCK = threading.Lock()  # batches run in threads: build a backend once, not once per thread


def get_perception(scene: SceneInput, cfg: PerceptionConfig) -> Perception:
    """The backend for this scene, built once per worker (models: once per worker for all scenes)."""
    cfg_json = cfg.model_dump_json()
    key = (cfg_json, "" if cfg.backend == "models" else str(scene.mesh_path))
    with _BUILD_LOCK:
        return _build(key, scene, cfg)


def _build(key: tuple[str, str], scene: SceneInput, cfg: PerceptionConfig) -> Perception:
    if key not in _BACKENDS:
        if cfg.backend == "models":
            from tasks.models import make_model_perception

            _BACKENDS[key] = make_model_perception(cfg)
        else:
            from react3d_core.perception import make_perception

            _BACKENDS[key] = make_perception(scene, cfg)
    return _BACKENDS[key]


def openable_phrases(kept: Sequence[str], cfg: PerceptionConfig) -> list[str]:
    """Text prompts for the segmenter: each kept tag as '<tag> door' (paper), 'door' itself as is."""
    out = []
    for t in sorted(set(kept) | set(cfg.always_keep_tags)):
        out.append(t if t.endswith("door") or t in cfg.always_keep_tags else t + cfg.prompt_suffix)
    return out


def _is_oom(exc: BaseException) -> bool:
    return "OutOfMemory" in type(exc).__name__ or "out of memory" in str(exc).lower()


def split_on_oom(fn: Callable[[list[Any], list[Any]], list[T]], frames: list[Any], images: list[Any]) -> list[T]:
    """Call ``fn`` on the batch; on a GPU OOM, call it on each half (down to single frames)."""
    try:
        return fn(frames, images)
    except Exception as exc:  # noqa: BLE001 - only OOM is handled, everything else re-raised
        if not _is_oom(exc) or len(frames) == 1:
            raise
        h = len(frames) // 2
        return split_on_oom(fn, frames[:h], images[:h]) + split_on_oom(fn, frames[h:], images[h:])


def perceive_body(scene_path: str, frames_cfg: dict[str, Any], frame_ids: list[str], perception_cfg: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    scene = scene_input(scene_path, frames_cfg)
    cfg = PerceptionConfig.model_validate(perception_cfg)
    perc = get_perception(scene, cfg)
    by_id = {f.frame_id: f for f in scene.frames}
    frames = [by_id[i] for i in frame_ids]
    images = [frame_rgb(f) for f in frames]
    tags = split_on_oom(lambda fr, im: perc.tagger.tag(fr, im), frames, images)
    all_tags = sorted({t for ts in tags for t in ts})
    kept = perc.tag_filter.filter(all_tags) if all_tags else []
    phrases = openable_phrases(kept, cfg)
    masks = split_on_oom(lambda fr, im: perc.segmenter.segment(fr, im, phrases), frames, images)
    preds = split_on_oom(lambda fr, im: perc.articulation.predict(fr, im), frames, images)
    result = {
        "masks": {fid: list(m) for fid, m in zip(frame_ids, masks)},
        "predictions": {fid: list(p) for fid, p in zip(frame_ids, preds)},
        "tags": {fid: list(t) for fid, t in zip(frame_ids, tags)},
        "phrases": phrases,
    }
    h = put(result, "perception")
    h["seconds"] = time.perf_counter() - t0
    h["n_masks"] = sum(len(m) for m in masks)
    h["frame_ids"] = list(frame_ids)  # lets per-part tasks open only the batches holding their views
    return h


@task(name="perceive-frames", cache_key_fn=content_key("perception", ("react3d_core.perception", "react3d_core.perception.heuristic",
                                                                    "react3d_core.perception.oracle", "tasks.models"),
                                                       ignore=("scene_path",)),
      retries=2, retry_delay_seconds=[2, 10], retry_condition_fn=retry_transient,
      result_serializer="json", cache_result_in_memory=False)
def perceive_frames(scene_path: str, scene_sha: str, frames_cfg: dict[str, Any], frame_ids: list[str],
                    perception_cfg: dict[str, Any]) -> dict[str, Any]:
    """Masks and articulation predictions for a batch of frames (a handle into the store)."""
    return perceive_body(scene_path, frames_cfg, frame_ids, perception_cfg)
