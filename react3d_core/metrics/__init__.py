"""Evaluation protocol of the paper: vertex-IoU detection, joint type / OE / MD, cumulative MOD."""

from ..geometry import iou_matrix
from .geometry import axis_error_deg, joint_class, line_distance
from .dirs import evaluate_dirs, find_pairs, run_evaluation
from .gt_as_prediction import gt_to_scene
from .scene_metrics import SceneMetrics, aggregate, evaluate_scene, evaluate_sets, summarize, to_json_dict
from .tables import markdown_table, write_tables

__all__ = [
    "SceneMetrics", "aggregate", "evaluate_dirs", "find_pairs", "run_evaluation", "axis_error_deg", "evaluate_scene", "evaluate_sets", "gt_to_scene", "iou_matrix",
    "joint_class", "line_distance", "markdown_table", "summarize", "to_json_dict", "write_tables",
]
