"""Task around :func:`react3d_core.pipeline.evaluate`: the paper's metrics of a converted scene against its
ground truth, also written to ``metrics.json`` in the output being staged."""

from __future__ import annotations

from typing import Any

from prefect import task

from react3d_core.config import EvaluationConfig
from react3d_core.pipeline import evaluate as evaluate_step


def evaluate_body(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    """The paper's metrics for this scene against its ground truth (per IoU threshold)."""
    return evaluate_step(manifest_path, gt_dir, EvaluationConfig.model_validate(config.get("evaluation", {})))


@task(name="evaluate-scene", persist_result=False)
def evaluate(manifest_path: str, gt_dir: str, config: dict[str, Any]) -> dict[str, Any]:
    return evaluate_body(manifest_path, gt_dir, config)
