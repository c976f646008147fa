"""Scene loading shared by all tasks of a worker: one SceneInput, mesh and rasterizer per scene.

Tasks receive the scene *path* (ignored by cache keys) and its content fingerprint (used by them);
each worker process loads a scene once and reuses it across tasks.
"""

from __future__ import annotations

import json
import time
from functools import lru_cache
from typing import Any

from prefect import task

from react3d_core.config import FrameSelectionConfig
from react3d_core.data.frames import SceneInput
from react3d_core.data.mesh import TriMesh, load_mesh
from react3d_core.raster import Rasterizer
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.scale import check_scale

from .store import tree_fingerprint


@lru_cache(maxsize=4)
def _scene(scene_path: str, frames_json: str) -> SceneInput:
    # the worker's cached rasterizer serves keyframe coverage and every later stage
    return load_scene(scene_path, FrameSelectionConfig.model_validate(json.loads(frames_json)),
                      rasterizer=lambda mesh_path: rasterizer(str(mesh_path)))


def scene_input(scene_path: str, frames_cfg: dict[str, Any]) -> SceneInput:
    return _scene(scene_path, json.dumps(frames_cfg, sort_keys=True))


@lru_cache(maxsize=2)
def scan_mesh(mesh_path: str) -> TriMesh:
    return load_mesh(mesh_path)


@lru_cache(maxsize=2)
def rasterizer(mesh_path: str) -> Rasterizer:
    return Rasterizer(scan_mesh(mesh_path))


def fingerprint_body(scene_path: str, frames_cfg: dict[str, Any]) -> dict[str, Any]:
    """Load and validate the scene (units included), select frames, hash its content (frames, mesh, GT)."""
    t0 = time.perf_counter()
    scene = scene_input(scene_path, frames_cfg)
    check_scale(scene, scan_mesh(str(scene.mesh_path)))  # a millimetre mesh otherwise gives 0 parts, rc 0
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
def fingerprint_scene(scene_path: str, frames_cfg: dict[str, Any]) -> dict[str, Any]:
    """Not cached: it is what computes the content hash every other key builds on."""
    return fingerprint_body(scene_path, frames_cfg)
