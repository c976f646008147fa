"""``convert(scene, out)``: the whole method in one process, without Prefect.

For notebooks, scripts and tests. It runs the same step functions as the Prefect flow
(``flows/convert_scene.py``), so its manifest (parts, joints, limits) is the flow's; what it lacks is
what Prefect adds: cached steps, retries, fan-out over workers, the UI. The output folder is written
the same way: staged beside ``out_dir`` and renamed onto it once complete.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..atomic import atomic_dir, check_output_dir
from ..config import PipelineConfig
from ..data.parts import InteractiveScene
from ..perception.interfaces import Perception
from . import steps
from .stages import manifest_versions

ProgressFn = Callable[[str, int, int], None]
"""``progress(stage, done, total)``, called as each stage advances (the CLI's progress bar)."""

OUTPUT_KIND = "scene"
"""The ``kind`` in the marker of a conversion output (``react3d_core.atomic.OUTPUT_MARKER``)."""


def output_marker(scene_path: str | Path | None = None) -> dict[str, Any]:
    """What a conversion output's marker records: that react3d wrote it, for which scan, when."""
    return {"kind": OUTPUT_KIND, "scene": str(Path(scene_path).resolve()) if scene_path else None,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


class StageClock:
    """Times stages into ``timings`` and reports their progress through ``progress``."""

    def __init__(self, progress: ProgressFn | None = None) -> None:
        self.progress = progress
        self.timings: dict[str, float] = {}

    @contextmanager
    def stage(self, name: str, total: int, record: bool = True) -> Iterator[Callable[..., Any]]:
        """``with clock.stage(name, n) as done: done(x, k)`` advances by ``k`` and returns ``x``."""
        t, count = time.perf_counter(), [0]
        if self.progress:
            self.progress(name, 0, total)

        def done(x: Any = None, n: int = 1) -> Any:
            count[0] += n
            if self.progress:
                self.progress(name, count[0], total)
            return x

        yield done
        if record:
            self.timings[name] = time.perf_counter() - t


def _physics(manifest: Path, cfg: PipelineConfig) -> None:
    """The physics check of the export beside ``manifest``, recorded in it; never fails the conversion."""
    try:
        result = steps.check_physics(manifest.parent, cfg.physics)
    except Exception as exc:  # noqa: BLE001 - reported, not raised: the scene itself is fine
        steps.record_physics(manifest, None, f"{type(exc).__name__}: {str(exc).strip()[:300]}")
        return
    steps.record_physics(manifest, result)


def convert(scene_path: str | Path, out_dir: str | Path, config: PipelineConfig | dict[str, Any] | None = None,
            perception: Perception | None = None, progress: ProgressFn | None = None) -> InteractiveScene:
    """Convert the scan at ``scene_path`` into ``out_dir``; returns the written manifest.

    ``perception``: a backend to use (default: the one the config names, built by
    :func:`react3d_core.perception.make_perception`; ``models`` needs the ``react3d_models`` package)."""
    t_all = time.perf_counter()
    out = check_output_dir(out_dir, (str(scene_path),), kind=OUTPUT_KIND)  # before any stage runs
    cfg = config if isinstance(config, PipelineConfig) else PipelineConfig().with_overrides(config or {})
    c = cfg.model_dump(mode="json")
    clock = StageClock(progress)

    t = time.perf_counter()
    loaded = steps.load(scene_path, cfg.frames)
    clock.timings["load"] = time.perf_counter() - t
    if perception is None:
        from ..perception import make_perception

        perception = make_perception(loaded.scene, cfg.perception)

    frames = loaded.scene.frames
    n = max(1, cfg.perception.batch_size)
    with clock.stage("perception", len(frames)) as done:
        perc = [done(steps.perceive(perception, frames[i:i + n], cfg.perception), len(frames[i:i + n]))
                for i in range(0, len(frames), n)]

    with clock.stage("segmentation", 1) as done:
        masks = steps.pack_masks(p["masks"] for p in perc)
        cands = done(steps.segment(loaded, masks, perception.point_segmenter, cfg))
    del masks

    preds = {fid: p for b in perc for fid, p in b["predictions"].items()}
    with clock.stage("articulation", len(cands)) as done:
        parts = [done(steps.articulate(loaded, cand, preds, cfg)) for cand in cands]

    formats = list(cfg.export.formats)
    with atomic_dir(out, marker=output_marker(scene_path)) as staging:
        manifest = staging / "scene.json"
        with clock.stage("assembly", 1) as done:
            done(steps.assemble(loaded, parts, cfg, staging))
        with clock.stage("export", 1, record=bool(formats)) as done:
            done(steps.export(manifest, formats, cfg.export) if formats else None)
        if formats and cfg.physics.enabled:
            with clock.stage("physics", 1) as done:
                done(_physics(manifest, cfg))
        metrics = None
        if loaded.scene.gt_dir is not None:
            t = time.perf_counter()
            metrics = steps.evaluate(manifest, loaded.scene.gt_dir, cfg.evaluation)
            clock.timings["evaluation"] = time.perf_counter() - t
        versions = manifest_versions()
        clock.timings["total"] = time.perf_counter() - t_all
        steps.finalize(manifest, c, versions, clock.timings)
        with clock.stage("report", 1) as done:
            done(steps.report(manifest, loaded.scene, metrics))
        steps.finalize(manifest, c, versions, clock.timings)
        check_output_dir(out, (str(scene_path),), kind=OUTPUT_KIND)  # nothing of the user's appeared there meanwhile
    return InteractiveScene.load(out / "scene.json")
