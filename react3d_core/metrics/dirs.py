"""Pair prediction folders (``scene.json``) with Articulate3D ground-truth folders and evaluate them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..atomic import write_json
from ..config.metrics import EvaluationConfig
from ..data.parts import InteractiveScene
from ..errors import InputError
from ..ground_truth.articulate3d import read_articulate3d
from .scene_metrics import SceneMetrics, evaluate_scene, to_json_dict
from .tables import write_tables


def find_pairs(pred_dir: str | Path, gt_dir: str | Path) -> list[tuple[Path, Path]]:
    """(prediction folder, GT folder) pairs. Either PRED_DIR holds scene.json (one scene, GT_DIR holds
    its ``<scan>_parts.json``) or PRED_DIR's sub-folders do; their GT is ``GT_DIR/<scene_id>/`` or
    GT_DIR itself when it holds ``<scene_id>_parts.json``."""
    pred_dir, gt_dir = Path(pred_dir), Path(gt_dir)
    if not pred_dir.is_dir():
        raise InputError(pred_dir, "prediction folder not found")
    if not gt_dir.is_dir():
        raise InputError(gt_dir, "ground-truth folder not found")
    if (pred_dir / "scene.json").is_file():
        return [(pred_dir, gt_dir)]
    pairs = []
    for sub in sorted(p for p in pred_dir.iterdir() if (p / "scene.json").is_file()):
        sid = InteractiveScene.load(sub).scene_id
        for cand in (gt_dir / sid, gt_dir / sub.name, gt_dir):
            if (cand / f"{sid}_parts.json").is_file():
                pairs.append((sub, cand))
                break
        else:
            raise InputError(gt_dir, f"no ground truth {sid}_parts.json for prediction {sub}")
    if not pairs:
        raise InputError(pred_dir, "no scene.json here nor in any sub-folder")
    return pairs


def evaluate_dirs(pred_dir: str | Path, gt_dir: str | Path, config: EvaluationConfig | None = None) -> list[SceneMetrics]:
    """Evaluate every paired scene (the scene id of the manifest names its GT scan)."""
    config = config or EvaluationConfig()
    out = []
    for p, g in find_pairs(pred_dir, gt_dir):
        pred = InteractiveScene.load(p)
        gt = read_articulate3d(g, pred.scene_id if (g / f"{pred.scene_id}_parts.json").is_file() else None)
        out.append(evaluate_scene(pred, p, gt, config))
    return out


def run_evaluation(pred_dir: str | Path, gt_dir: str | Path, out_dir: str | Path | None = None,
                   config: dict[str, Any] | None = None) -> dict[str, Any]:
    """Evaluate, and with ``out_dir`` write metrics.json, parts.parquet, scenes.parquet, metrics.md.
    Returns the JSON dict of :func:`to_json_dict`."""
    scenes = evaluate_dirs(pred_dir, gt_dir, EvaluationConfig(**(config or {})))
    result = to_json_dict(scenes)
    if out_dir is not None:
        write_tables(out_dir, scenes)
        write_json(Path(out_dir) / "metrics.json", result)
    return result
