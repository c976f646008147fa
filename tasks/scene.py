"""Scene loading shared by all tasks of a worker: one loaded scene (frames, mesh, rasterizer) per scan.

Tasks receive the scene *path* (ignored by cache keys) and its content fingerprint (used by them);
each worker process loads a scene once and reuses it across tasks.
"""

from __future__ import annotations

import json
import time
from functools import lru_cache
from pathlib import Path
from typing import Any

from prefect import task

from react3d_core.atomic import atomic_path
from react3d_core.config import FrameSelectionConfig
from react3d_core.data.mesh import load_mesh
from react3d_core.pipeline import LoadedScene, load
from react3d_core.raster import Rasterizer

from .store import cache_root, tree_fingerprint


@lru_cache(maxsize=2)
def rasterizer(mesh_path: str) -> Rasterizer:
    """The worker's rasterizer (and mesh, ``.mesh``) of a scan: keyframe coverage and every later stage."""
    return Rasterizer(load_mesh(mesh_path))


class CachedSelections:
    """Keyframe selections remembered in the local cache (``$REACT3D_CACHE/selections/<key>.json``), keyed
    by what they depend on (``react3d_core.scene_io.selection.selection_key``): a re-run of a capture
    does not render its frames again to choose them (2-3 s of a cached RedKitchen convert)."""

    def _path(self, key: str) -> Path:
        return cache_root() / "selections" / key[:2] / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        try:
            value = json.loads(self._path(key).read_text())
        except (OSError, ValueError):
            return None  # missing or unreadable: select again (and rewrite it)
        return value if isinstance(value, dict) else None

    def put(self, key: str, value: dict[str, Any]) -> None:
        path = self._path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps(value))


@lru_cache(maxsize=4)
def _loaded(scene_path: str, frames_json: str) -> LoadedScene:
    return load(scene_path, FrameSelectionConfig.model_validate(json.loads(frames_json)),
                raster_for=lambda mesh_path: rasterizer(str(mesh_path)), memo=CachedSelections(),
                cache_dir=cache_root())  # completed scans live beside the rest of the worker's store


def loaded_scene(scene_path: str, config: dict[str, Any]) -> LoadedScene:
    """The scan at ``scene_path`` with the frames ``config["frames"]`` selects (once per worker)."""
    return _loaded(scene_path, json.dumps(config.get("frames", {}), sort_keys=True))


def fingerprint_body(scene_path: str, config: dict[str, Any]) -> dict[str, Any]:
    """Load and validate the scene (units included), select frames, hash its content (frames, mesh, GT)."""
    t0 = time.perf_counter()
    scene = loaded_scene(scene_path, config).scene
    sha = tree_fingerprint(scene_path, exclude=("report", "export"))
    return {
        "sha256": sha,
        "scene_id": scene.scene_id,
        "frame_ids": [f.frame_id for f in scene.frames],
        "frame_selection": scene.frame_selection,
        "mesh_path": str(scene.mesh_path),
        "has_gt": scene.gt_dir is not None,
        "gt_dir": str(scene.gt_dir) if scene.gt_dir is not None else None,
        "seconds": time.perf_counter() - t0,
    }


@task(name="load-scene", retries=0, persist_result=False)
def fingerprint_scene(scene_path: str, config: dict[str, Any]) -> dict[str, Any]:
    """Not cached: it is what computes the content hash every other key builds on."""
    return fingerprint_body(scene_path, config)
