"""Last steps in the output folder: record config/versions/timings, evaluate against GT, write report.html."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from prefect import task

from react3d_core.atomic import write_json
from react3d_core.config import PipelineConfig
from react3d_core.data.parts import InteractiveScene

from .scene import scene_input


def finalize_body(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    m = InteractiveScene.load(manifest_path)
    m.model_copy(update={"config": config, "versions": {**m.versions, **versions},
                         "timings": {**m.timings, **timings}}).save(manifest_path)
    return manifest_path


def evaluate_body(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    """The paper's metrics for this scene against its ground truth (per IoU threshold)."""
    from react3d_core.ground_truth import read_articulate3d
    from react3d_core.metrics import evaluate_scene, to_json_dict

    cfg = PipelineConfig.model_validate(config)
    pred = InteractiveScene.load(manifest_path)
    gt = read_articulate3d(gt_dir)
    metrics = evaluate_scene(pred, Path(manifest_path).parent, gt, cfg.evaluation)
    out = to_json_dict([metrics])
    write_json(Path(manifest_path).parent / "metrics.json", out)
    return out


def report_body(manifest_path: str, scene_path: str, frames_cfg: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    from react3d_core.viewer import write_report

    per_tau = None
    if metrics:
        per_tau = metrics.get("aggregate", metrics)
    from .store import cache_root

    # thumbnails and viewer meshes by content: a re-convert of the same scene does not redo them
    return str(write_report(manifest_path, scene_input=scene_input(scene_path, frames_cfg), metrics=per_tau,
                            cache_dir=cache_root() / "reports"))


@task(name="evaluate-scene", persist_result=False)
def evaluate(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    return evaluate_body(manifest_path, gt_dir, config)


@task(name="write-report", persist_result=False)
def report(manifest_path: str, scene_path: str, frames_cfg: dict[str, Any], metrics: dict[str, Any] | None) -> str:
    return report_body(manifest_path, scene_path, frames_cfg, metrics)


@task(name="finalize-manifest", persist_result=False)
def finalize(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    return finalize_body(manifest_path, config, versions, timings)
