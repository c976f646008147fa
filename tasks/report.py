"""Last steps in the output folder, around the pipeline's step functions: record config, versions and
timings; evaluate against GT; write report.html."""

from __future__ import annotations

from typing import Any

from prefect import task

from react3d_core.config import EvaluationConfig
from react3d_core.pipeline import evaluate as evaluate_step
from react3d_core.pipeline import finalize as finalize_step
from react3d_core.pipeline import report as report_step

from .scene import loaded_scene
from .store import cache_root


def finalize_body(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    finalize_step(manifest_path, config, versions, timings)
    return manifest_path


def evaluate_body(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    """The paper's metrics for this scene against its ground truth (per IoU threshold)."""
    return evaluate_step(manifest_path, gt_dir, EvaluationConfig.model_validate(config.get("evaluation", {})))


def report_body(manifest_path: str, scene_path: str, config: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    # thumbnails and viewer meshes by content: a re-convert of the same scene does not redo them
    return str(report_step(manifest_path, loaded_scene(scene_path, config).scene, metrics, cache_dir=cache_root() / "reports"))


@task(name="evaluate-scene", persist_result=False)
def evaluate(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    return evaluate_body(manifest_path, gt_dir, config)


@task(name="write-report", persist_result=False)
def report(manifest_path: str, scene_path: str, config: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    return report_body(manifest_path, scene_path, config, metrics)


@task(name="finalize-manifest", persist_result=False)
def finalize(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    return finalize_body(manifest_path, config, versions, timings)
