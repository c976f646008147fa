"""Evaluation protocol thresholds (paper, Sec. Experiments)."""

from pydantic import Field

from ._base import StageConfig


class EvaluationConfig(StageConfig):
    """Matching and articulation thresholds."""

    iou_thresholds: tuple[float, ...] = Field((0.25, 0.5), description="Vertex-IoU thresholds for a TP.")
    horizontal_deg: float = Field(45.0, description="Revolute axis is horizontal if its angle with the ground < this.")
    oe_deg: float = Field(10.0, description="+MO: axis error below this (deg).")
    md_factor: float = Field(0.25, description="+MOD: MD below this x GT part mesh diagonal.")
