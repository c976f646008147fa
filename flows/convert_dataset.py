"""Flow ``convert_dataset``: many scenes, each a subflow; one failed scene never fails the others.

Scenes run ``scene_concurrency`` at a time (threads in this process; for process isolation on a
cluster use the deployment in deployments/prefect.yaml, one flow run per scene). The run ends with a
table artifact of succeeded/failed scenes with reasons, and returns the same rows.
"""

from __future__ import annotations

import fnmatch
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from tasks import prefect_env

prefect_env.configure()

from prefect import flow  # noqa: E402

from react3d_core.atomic import check_output_dir  # noqa: E402
from react3d_core.errors import InputError  # noqa: E402
from tasks.assembly import OUTPUT_KIND  # noqa: E402

from .convert_scene import convert_scene  # noqa: E402


def find_scenes(root: str | Path, scene_ids: list[str] | None = None, glob: str | None = None) -> list[Path]:
    """Scene folders under ``root``: the named ids, or those matching ``glob`` (default: every folder
    that looks like a scan: has scans/, iphone/, a mesh or a transforms.json)."""
    root = Path(root)
    if scene_ids:
        return [root / s for s in scene_ids]
    found = []
    for d in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        if glob and not fnmatch.fnmatch(d.name, glob):
            continue
        if glob or any((d / n).exists() for n in ("scans", "iphone", "dslr", "mesh_aligned_0.05.ply", "transforms.json")):
            found.append(d)
    return found


def check_dataset_outputs(root: str | Path, scene_ids: list[str] | None, glob: str | None,
                          out_root: str | Path) -> list[Path]:
    """Refuse the whole run before any scene starts when one scene's output folder is unsafe to replace
    (see :func:`react3d_core.atomic.check_output_dir`) or a scene id is not a plain folder name
    (``..`` would put a scene's output at the parent of ``out_root``). Returns the scenes."""
    root_p = Path(root)
    if not root_p.is_dir():
        raise InputError(root_p, "dataset folder not found")
    for s in scene_ids or []:
        if s in ("", ".", "..") or "/" in s or "\\" in s:
            raise InputError(root_p / s, "a scene id must be the name of a sub-folder of the dataset folder")
    out = Path(out_root)
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise InputError(out, "exists and is not a folder; choose a new --out folder")
    scenes = find_scenes(root_p, scene_ids, glob)
    for scene in scenes:
        check_output_dir(out / scene.name, (scene, root_p), kind=OUTPUT_KIND)
    return scenes


def _one(scene: Path, out_root: Path, config: dict[str, Any] | None) -> dict[str, Any]:
    t0 = time.perf_counter()
    try:
        manifest = convert_scene.with_options(name=f"convert-{scene.name}")(str(scene), str(out_root / scene.name), config)
        from react3d_core.data.parts import InteractiveScene

        n = len(InteractiveScene.load(manifest).objects)
        return {"scene": scene.name, "status": "ok", "parts": n, "seconds": round(time.perf_counter() - t0, 1),
                "manifest": manifest, "error": ""}
    except Exception as exc:  # noqa: BLE001 - a failed scene is reported, the others go on
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        return {"scene": scene.name, "status": "failed", "parts": 0, "seconds": round(time.perf_counter() - t0, 1),
                "manifest": "", "error": f"{type(exc).__name__}: {msg}"[:300]}


@flow(name="react3d-convert-dataset", persist_result=False)
def convert_dataset(root: str, scene_ids: list[str] | None = None, glob: str | None = None,
                    out_root: str = "react3d_out", config: dict[str, Any] | None = None,
                    scene_concurrency: int = 1) -> list[dict[str, Any]]:
    """Convert every selected scene under ``root`` into ``out_root/<scene>``; returns one row per scene."""
    scenes = check_dataset_outputs(root, scene_ids, glob, out_root)
    out = Path(out_root)
    rows: list[dict[str, Any]] = []
    progress = None
    try:
        from prefect.artifacts import create_progress_artifact, update_progress_artifact

        progress = create_progress_artifact(0.0, description=f"{len(scenes)} scenes")
    except Exception:  # noqa: BLE001
        pass
    with ThreadPoolExecutor(max_workers=max(1, scene_concurrency)) as pool:
        for row in pool.map(lambda s: _one(s, out, config), scenes):
            rows.append(row)
            if progress is not None:
                try:
                    update_progress_artifact(progress, 100.0 * len(rows) / max(len(scenes), 1))
                except Exception:  # noqa: BLE001
                    pass
    try:
        from prefect.artifacts import create_table_artifact

        create_table_artifact([{k: r[k] for k in ("scene", "status", "parts", "seconds", "error")} for r in rows],
                              key="dataset-summary", description=f"{sum(r['status'] == 'ok' for r in rows)}/{len(rows)} scenes converted")
    except Exception:  # noqa: BLE001
        pass
    return rows
