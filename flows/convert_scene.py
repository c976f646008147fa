"""Flow ``convert_scene``: one scan -> interactive scene (manifest, meshes, URDF/USD/MJCF, report).

Fan-out: perception per batch of frames (GPU-capped with the ``gpu`` tag for model backends) and
articulation per candidate part; fan-in: fusion, assembly (dedup, cavities, limits, carving), export.
Every compute task is cached by content (tasks/keys.py), so re-running a finished scene is cheap and a
crashed run resumes from the last finished task.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from tasks import prefect_env

prefect_env.configure()

from prefect import flow  # noqa: E402
from prefect.task_runners import ThreadPoolTaskRunner  # noqa: E402

from react3d_core.config import PipelineConfig  # noqa: E402
from tasks.articulation import articulate_part  # noqa: E402
from react3d_core.atomic import atomic_dir, check_output_dir  # noqa: E402
from tasks.assembly import OUTPUT_KIND, assemble, export, output_marker, stage_output  # noqa: E402
from tasks.keys import stage_version  # noqa: E402
from tasks.perception import perceive_frames  # noqa: E402
from tasks.report import evaluate, finalize, report  # noqa: E402
from tasks import storage  # noqa: E402
from tasks.scene import fingerprint_scene  # noqa: E402
from tasks.segmentation import segment_scene  # noqa: E402

from .artifacts import publish_scene_artifacts, Progress  # noqa: E402
from .server_watchdog import install as _install_server_watchdog  # noqa: E402

_install_server_watchdog()  # Prefect's temporary server ends with this process, even after kill -9

STAGE_MODULES = ("react3d_core.scene_io", "react3d_core.perception", "react3d_core.perception.heuristic",
                 "react3d_core.perception.oracle", "react3d_core.fusion", "react3d_core.articulation",
                 "react3d_core.cavity", "react3d_core.dedup", "react3d_core.assembly", "react3d_core.texture",
                 "react3d_core.export")

# Each task gets only the config sections it depends on, so its cache key changes exactly when they do.
SEGMENTATION_KEYS = ("frames", "perception", "fusion", "topk", "clip")
ARTICULATION_KEYS = ("frames", "perception", "topk", "articulation")
ASSEMBLY_KEYS = ("frames", "articulation", "limits", "cavity", "dedup", "assembly")


def config_sections(c: dict[str, Any], keys: tuple[str, ...]) -> dict[str, Any]:
    return {k: c[k] for k in keys if k in c}


# The CLI sets this to drive its progress bar: hook(stage, done, total).
PROGRESS_HOOK: Callable[[str, int, int], None] | None = None


@contextmanager
def _stage(name: str, total: int, prog: Progress, timings: dict[str, float]) -> Iterator[Callable[..., Any]]:
    """Time a stage into ``timings`` and report progress; ``done(x, n=1)`` advances and returns ``x``."""
    t = time.perf_counter()
    prog.start(name, total)

    def done(x: Any = None, n: int = 1) -> Any:
        prog.advance(name, n)
        return x

    yield done
    timings[name] = time.perf_counter() - t


def _chunks(items: list[str], n: int) -> list[list[str]]:
    return [items[i:i + n] for i in range(0, len(items), n)]


@flow(name="react3d-convert-scene", task_runner=ThreadPoolTaskRunner(max_workers=4), persist_result=False)
def convert_scene(scene_path: str, out_dir: str, config: dict[str, Any] | None = None) -> str:
    """Convert the scan at ``scene_path`` into ``out_dir`` (a folder, or an fsspec URL such as
    ``s3://bucket/out/scene``); returns the manifest path or URL (``scene.json``)."""
    t_all = time.perf_counter()
    remote_out = out_dir if storage.is_remote(out_dir) else None
    if remote_out:  # s3://... : built in a local folder, uploaded once complete (tasks/storage.py)
        storage.check_remote_output(remote_out)
        out_dir = str(storage.staging_dir(remote_out))
    out = check_output_dir(out_dir, (scene_path,), kind=OUTPUT_KIND)  # before any stage runs
    cfg = PipelineConfig().with_overrides(config or {})
    c = cfg.model_dump(mode="json")
    frames_cfg = c["frames"]
    prog = Progress(PROGRESS_HOOK)
    timings: dict[str, float] = {}

    t = time.perf_counter()
    fp = fingerprint_scene(scene_path, frames_cfg)
    timings["load"] = time.perf_counter() - t
    sha = fp["sha256"]
    batches = _chunks(fp["frame_ids"], max(1, cfg.perception.batch_size))

    with _stage("perception", len(fp["frame_ids"]), prog, timings) as done:
        tags = ["gpu"] if cfg.perception.backend == "models" else []
        futs = [perceive_frames.with_options(tags=tags).submit(scene_path, sha, frames_cfg, b, c["perception"]) for b in batches]
        perc = [done(f.result(), len(b)) for f, b in zip(futs, batches)]

    with _stage("segmentation", 1, prog, timings) as done:
        seg = done(segment_scene(scene_path, sha, frames_cfg, perc, config_sections(c, SEGMENTATION_KEYS)))

    with _stage("articulation", seg["n"], prog, timings) as done:
        ac = config_sections(c, ARTICULATION_KEYS)
        futs = [articulate_part.submit(scene_path, sha, frames_cfg, seg, i, perc, ac) for i in range(seg["n"])]
        parts = [done(f.result()) for f in futs]

    with _stage("assembly", 1, prog, timings) as done:
        asm = done(assemble(scene_path, sha, frames_cfg, parts, config_sections(c, ASSEMBLY_KEYS)))

    formats = list(cfg.export.formats)
    metrics = None
    versions = {m: stage_version(m) for m in STAGE_MODULES}
    # Everything the user gets (manifest with config and timings, metrics, report) is built in a staging
    # sibling and renamed onto ``out`` in one step: a kill at any point leaves the old output as it was.
    with atomic_dir(out, marker=output_marker(scene_path)) as staging:
        with _stage("export", 1, prog, timings if formats else {}) as done:
            # no formats (accuracy benchmarks): publish the assembled scene without simulator files
            exp = export(asm, c["export"], formats) if formats else asm
            staged = done(stage_output(exp, str(staging), str(out), fp["mesh_path"]))
        if fp["gt_dir"]:
            t = time.perf_counter()
            metrics = evaluate(staged, fp["gt_dir"], c)
            timings["evaluation"] = time.perf_counter() - t
        timings["total"] = time.perf_counter() - t_all
        finalize(staged, c, versions, timings)
        with _stage("report", 1, prog, timings) as done:
            done(report(staged, scene_path, frames_cfg, metrics))
        finalize(staged, c, versions, timings)
        check_output_dir(out, (scene_path,), kind=OUTPUT_KIND)  # nothing of the user's appeared there meanwhile
    manifest, html = str(out / "scene.json"), str(out / "report.html")
    if remote_out:
        manifest = storage.publish_tree(out, remote_out)
    publish_scene_artifacts(fp["scene_id"], manifest, html, timings, metrics,
                            n_candidates=seg["n"], n_rejected=sum(p.get("kind") == "rejected" for p in parts))
    return manifest
