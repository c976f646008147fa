"""Scene-level tasks after articulation: dedup + cavity + limits + carving (assembly), export, publish.

Assembly and export write folders into the content store (``$REACT3D_CACHE/scenes/<hash>``), so a
cached result stays complete whatever happens to the output folder; ``publish`` copies the final folder
to the user's output atomically (never a half-written result).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from pathlib import Path
from typing import Any

from prefect import task

from react3d_core.atomic import atomic_dir, check_output_dir
from react3d_core.config import ExportConfig
from react3d_core.pipeline import OUTPUT_KIND, key_material, output_marker, step_config
from react3d_core.pipeline import assemble as assemble_step
from react3d_core.pipeline import export as export_step

from .keys import canonical, content_key
from .scene import loaded_scene
from .store import cache_root, get, relative, resolve, seal_dir

COMPLETED_SCAN = "scan_completed.ply"  # a result's own copy of a scan this program completed

__all__ = ["OUTPUT_KIND", "assemble", "export", "fill_output", "output_marker", "publish", "publish_body", "stage_output"]


def _dir_for(stage: str, inputs: Any) -> Path:
    sha = hashlib.sha256(json.dumps([stage, canonical(inputs)], sort_keys=True, default=str).encode()).hexdigest()
    return cache_root() / "scenes" / sha[:2] / f"{stage}-{sha[:32]}"


def assemble_body(scene_path: str, scene_sha: str, parts: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    loaded = loaded_scene(scene_path, config)
    out = _dir_for("assembly", [scene_sha, parts, key_material("assembly", config)])
    arts = [get(h) for h in parts if h.get("kind") != "rejected"]
    with atomic_dir(out) as tmp:
        assemble_step(loaded, arts, config, tmp)
    seal_dir(out)  # cache hits are verified against it (tasks.store.verify_dir)
    return {"sha256": out.name, "path": relative(out / "scene.json"), "kind": "assembled-scene",
            "seconds": time.perf_counter() - t0}


@task(name="assemble-scene", cache_key_fn=content_key("assembly"), result_serializer="json", cache_result_in_memory=False)
def assemble(scene_path: str, scene_sha: str, parts: list[dict[str, Any]], config: dict[str, Any]) -> dict[str, Any]:
    """Deduplicate, add cavities and limits, carve the background; a manifest folder in the store."""
    return assemble_body(scene_path, scene_sha, parts, step_config("assembly", config))


def export_body(assembled: dict[str, Any], config: dict[str, Any], formats: list[str]) -> dict[str, Any]:
    t0 = time.perf_counter()
    src = resolve(assembled["path"]).parent
    out = _dir_for("export", [assembled, formats, key_material("export", config)])
    with atomic_dir(out) as tmp:
        shutil.copytree(src, tmp, dirs_exist_ok=True)
        export_step(tmp / "scene.json", formats, ExportConfig.model_validate(config.get("export", {})))
    seal_dir(out)
    return {"sha256": out.name, "path": relative(out / "scene.json"), "kind": "exported-scene",
            "seconds": time.perf_counter() - t0}


@task(name="export-scene", cache_key_fn=content_key("export"), result_serializer="json", cache_result_in_memory=False)
def export(assembled: dict[str, Any], config: dict[str, Any], formats: list[str]) -> dict[str, Any]:
    """URDF / USD / MJCF with textures and collisions, in the store."""
    return export_body(assembled, step_config("export", config), formats)


def fill_output(result: dict[str, Any], staging: str | Path, out_dir: str | Path,
                scan_mesh_path: str | None = None) -> str:
    """Copy the finished store folder into ``staging`` (a sibling of ``out_dir`` that will be renamed onto
    it); returns the staged manifest path.

    The stored result is keyed by content, so it may come from a run on another copy of the scan:
    ``scan_mesh_path`` (this run's mesh) is what the published manifest refers to, relative to
    ``out_dir`` (the same relative path from the staging sibling)."""
    from react3d_core.data.parts import InteractiveScene

    src = resolve(result["path"]).parent
    staging, out = Path(staging), Path(out_dir)
    if staging.parent.resolve() != out.parent.resolve():
        raise ValueError(f"staging folder {staging} must be a sibling of {out}")
    manifest = InteractiveScene.load(src / "scene.json")
    mesh = Path(scan_mesh_path) if scan_mesh_path else Path(manifest.input_mesh)
    mesh = mesh.resolve() if mesh.is_absolute() or scan_mesh_path else (src / mesh).resolve()
    _copy_folder(src, staging)
    if mesh.is_relative_to(cache_root().resolve()):
        # a scan this program completed (slabs over surfaces the sensor missed) lives in the cache, which
        # is pruned (and a benchmark's cold cache removed): the result keeps its own copy
        shutil.copy2(mesh, staging / COMPLETED_SCAN)
        rel = COMPLETED_SCAN
    else:
        # the scan mesh stays where it is: re-point the manifest's reference from the new folder
        rel = os.path.relpath(mesh, out.resolve())
    manifest.model_copy(update={"input_mesh": rel}).save(staging / "scene.json")
    return str(staging / "scene.json")


def _copy_folder(src: Path, dst: Path) -> None:
    """Copy ``src`` into ``dst``, stopping at the first failure with one OSError naming the target file
    (``shutil.copytree`` collects every failed file into one exception: 642 KB for a full disk)."""
    for p in sorted(src.rglob("*")):
        target = dst / p.relative_to(src)
        try:
            if p.is_dir():
                target.mkdir(parents=True, exist_ok=True)
            else:
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(p, target)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(target)) from None


def publish_body(result: dict[str, Any], out_dir: str, scan_mesh_path: str | None = None,
                 inputs: tuple[str, ...] = ()) -> str:
    """Copy the finished folder to ``out_dir`` as a whole (atomic rename); returns the manifest path.

    ``out_dir`` is checked first (:func:`react3d_core.atomic.check_output_dir`): only a new/empty folder
    or a previous react3d output that holds none of ``inputs`` is replaced. The flow does not use this:
    it stages the manifest, metrics and report together (``flows/convert_scene.py``)."""
    out = check_output_dir(out_dir, inputs, kind=OUTPUT_KIND)
    with atomic_dir(out, marker=output_marker(inputs[0] if inputs else None)) as tmp:
        fill_output(result, tmp, out, scan_mesh_path)
    return str(out / "scene.json")


@task(name="publish", persist_result=False)
def publish(result: dict[str, Any], out_dir: str, scan_mesh_path: str | None = None) -> str:
    return publish_body(result, out_dir, scan_mesh_path)


@task(name="stage-output", persist_result=False)
def stage_output(result: dict[str, Any], staging: str, out_dir: str, scan_mesh_path: str | None = None) -> str:
    """Fill the staging folder that becomes ``out_dir`` once the report is written too."""
    return fill_output(result, staging, out_dir, scan_mesh_path)
