"""Flow ``convert_scene``: one scan -> interactive scene (manifest, meshes, URDF/USD/MJCF, report).

Fan-out: perception per batch of frames (GPU-capped with the ``gpu`` tag for model backends) and
articulation per candidate part; fan-in: fusion, assembly (dedup, cavities, limits, carving), export.
Every compute task is cached by content (tasks/keys.py), so re-running a finished scene is cheap and a
crashed run resumes from the last finished task.
"""

from __future__ import annotations

import time
from typing import Any

from tasks import prefect_env
from tasks.memory import limit_malloc_arenas

prefect_env.configure()
limit_malloc_arenas()  # before the task runner's threads exist: two heaps, not one per thread (tasks/memory.py)

from prefect import flow  # noqa: E402
from prefect.task_runners import ThreadPoolTaskRunner  # noqa: E402

from react3d_core.atomic import atomic_dir, check_output_dir  # noqa: E402
from react3d_core.config import PipelineConfig  # noqa: E402
from react3d_core.pipeline import (OUTPUT_KIND, ProgressFn, StageClock, manifest_versions, output_marker,  # noqa: E402
                                   record_physics)
from tasks import scan_cache, storage  # noqa: E402
from tasks.articulation import articulate_part  # noqa: E402
from tasks.assembly import assemble, export, stage_output  # noqa: E402
from tasks.evaluation import evaluate  # noqa: E402
from tasks.manifest import finalize  # noqa: E402
from tasks.perception import perceive_frames  # noqa: E402
from tasks.physics import check_physics  # noqa: E402
from tasks.report import report  # noqa: E402
from tasks.scene import fingerprint_scene  # noqa: E402
from tasks.segmentation import segment_scene  # noqa: E402

from .artifacts import Progress, publish_scene_artifacts  # noqa: E402
from .server_watchdog import install as _install_server_watchdog  # noqa: E402

_install_server_watchdog()  # Prefect's temporary server ends with this process, even after kill -9


def _chunks(items: list[str], n: int) -> list[list[str]]:
    return [items[i:i + n] for i in range(0, len(items), n)]


def _physics(exported: dict[str, Any], config: dict[str, Any], manifest: str) -> None:
    """Run the (cached) physics check and record it in the staged output; a check that cannot run is
    reported in the manifest and never fails the conversion."""
    try:
        result = check_physics(exported, config)
    except Exception as exc:  # noqa: BLE001 - reported, not raised: the scene itself is fine
        record_physics(manifest, None, f"{type(exc).__name__}: {str(exc).strip()[:300]}")
        return
    record_physics(manifest, result)


@flow(name="react3d-convert-scene", task_runner=ThreadPoolTaskRunner(max_workers=4), persist_result=False)
def convert_scene(scene_path: str, out_dir: str, config: dict[str, Any] | None = None,
                  progress: ProgressFn | None = None) -> str:
    """Convert the scan at ``scene_path`` (a folder, or a URL such as ``s3://bucket/scans/scene``, read
    through this machine's scan cache: tasks/scan_cache.py) into ``out_dir`` (a folder, or an fsspec URL
    such as ``s3://bucket/out/scene``); returns the manifest path or URL (``scene.json``).

    ``progress(stage, done, total)`` is called as stages advance (the CLI's progress bar); each task is
    handed the whole config and keys and reads only the sections its stages declare."""
    if storage.is_remote(scene_path):  # the local copy stays in the cache until the conversion ends
        with scan_cache.local_scene(scene_path) as local:
            return _convert(str(local), out_dir, config, progress)
    return _convert(scene_path, out_dir, config, progress)


def _convert(scene_path: str, out_dir: str, config: dict[str, Any] | None, progress: ProgressFn | None) -> str:
    """The body of :func:`convert_scene` for a scan in a local folder."""
    t_all = time.perf_counter()
    remote_out = out_dir if storage.is_remote(out_dir) else None
    if remote_out:  # s3://... : built in a local folder, uploaded once complete (tasks/storage.py)
        storage.check_remote_output(remote_out)
        out_dir = str(storage.staging_dir(remote_out))
    out = check_output_dir(out_dir, (scene_path,), kind=OUTPUT_KIND)  # before any stage runs
    cfg = PipelineConfig().with_overrides(config or {})
    c = cfg.model_dump(mode="json")
    clock = StageClock(Progress(progress))

    t = time.perf_counter()
    fp = fingerprint_scene(scene_path, c)
    clock.timings["load"] = time.perf_counter() - t
    sha = fp["sha256"]
    batches = _chunks(fp["frame_ids"], max(1, cfg.perception.batch_size))

    with clock.stage("perception", len(fp["frame_ids"])) as done:
        tags = ["gpu"] if cfg.perception.backend == "models" else []
        futs = [perceive_frames.with_options(tags=tags).submit(scene_path, sha, b, c) for b in batches]
        perc = [done(f.result(), len(b)) for f, b in zip(futs, batches)]

    with clock.stage("segmentation", 1) as done:
        seg = done(segment_scene(scene_path, sha, perc, c))

    with clock.stage("articulation", seg["n"]) as done:
        futs = [articulate_part.submit(scene_path, sha, seg, i, perc, c) for i in range(seg["n"])]
        parts = [done(f.result()) for f in futs]

    with clock.stage("assembly", 1) as done:
        asm = done(assemble(scene_path, sha, parts, c))

    formats = list(cfg.export.formats)
    metrics = None
    versions = manifest_versions()
    # Everything the user gets (manifest with config and timings, metrics, report) is built in a staging
    # sibling and renamed onto ``out`` in one step: a kill at any point leaves the old output as it was.
    with atomic_dir(out, marker=output_marker(scene_path)) as staging:
        with clock.stage("export", 1, record=bool(formats)) as done:
            # no formats (accuracy benchmarks): publish the assembled scene without simulator files
            exp = export(asm, c, formats) if formats else asm
            staged = done(stage_output(exp, str(staging), str(out), fp["mesh_path"]))
        if formats and cfg.physics.enabled:
            with clock.stage("physics", 1) as done:
                done(_physics(exp, c, staged))
        if fp["gt_dir"]:
            t = time.perf_counter()
            metrics = evaluate(staged, fp["gt_dir"], c)
            clock.timings["evaluation"] = time.perf_counter() - t
        clock.timings["total"] = time.perf_counter() - t_all
        finalize(staged, c, versions, clock.timings)
        with clock.stage("report", 1) as done:
            done(report(staged, scene_path, c, metrics))
        finalize(staged, c, versions, clock.timings)
        check_output_dir(out, (scene_path,), kind=OUTPUT_KIND)  # nothing of the user's appeared there meanwhile
    manifest, html = str(out / "scene.json"), str(out / "report.html")
    if remote_out:
        manifest = storage.publish_tree(out, remote_out)
    publish_scene_artifacts(fp["scene_id"], manifest, html, clock.timings, metrics,
                            n_candidates=seg["n"], n_rejected=sum(p.get("kind") == "rejected" for p in parts))
    return manifest
