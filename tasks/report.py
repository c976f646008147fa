"""Task around :func:`react3d_core.pipeline.report`: ``report.html`` (the viewer with the parts, metrics
and timings) in the output being staged."""

from __future__ import annotations

from typing import Any

from prefect import task

from react3d_core.pipeline import report as report_step

from .scene import loaded_scene
from .store import cache_root


def report_body(manifest_path: str, scene_path: str, config: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    # thumbnails and viewer meshes by content: a re-convert of the same scene does not redo them
    return str(report_step(manifest_path, loaded_scene(scene_path, config).scene, metrics, cache_dir=cache_root() / "reports"))


@task(name="write-report", persist_result=False)
def report(manifest_path: str, scene_path: str, config: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    return report_body(manifest_path, scene_path, config, metrics)
