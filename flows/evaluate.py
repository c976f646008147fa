"""Prefect flow ``evaluate(pred_dir, gt_dir)``: score converted scenes against Articulate3D GT and
write metrics.json, parts.parquet, scenes.parquet and metrics.md (the CLI calls the same body,
``react3d_core.metrics.run_evaluation``, without starting Prefect)."""

from __future__ import annotations

from typing import Any

from prefect import flow

from react3d_core.metrics import run_evaluation


@flow(name="react3d-evaluate")
def evaluate(pred_dir: str, gt_dir: str, out_dir: str | None = None, config: dict[str, Any] | None = None) -> dict[str, Any]:
    """Evaluate PRED_DIR (scene.json, or sub-folders with one) against GT_DIR; returns the JSON dict."""
    return run_evaluation(pred_dir, gt_dir, out_dir, config)
