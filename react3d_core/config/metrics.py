"""Evaluation protocol thresholds (paper, Sec. Experiments)."""

from pydantic import Field

from ._base import StageConfig


class EvaluationConfig(StageConfig):
    """Matching and articulation thresholds."""

    iou_thresholds: tuple[float, ...] = Field((0.25, 0.5), description="Vertex-IoU thresholds for a TP.")
    horizontal_deg: float = Field(45.0, description="Revolute axis is horizontal if its angle with the ground < this.")
    oe_deg: float = Field(10.0, description="+MO: axis error below this (deg).")
    md_factor: float = Field(0.25, description="+MOD: MD below this x GT part mesh diagonal.")
    box_below_coverage: float = Field(0.5, ge=0, le=1, description="A GT part whose annotation gives its box and a scan coverage below this (or no scan vertices) is matched by front-box IoU instead of vertex IoU.")
    box_slab_tol: float = Field(0.05, ge=0, description="Front-box IoU: a prediction's box must lie within the GT front's slab grown by this (m) on both sides.")
    miss_iou: float = Field(0.5, ge=0, le=1, description="Miss causes: a GT part below this vertex IoU is traced through the stages.")
    cause_min_views: int = Field(2, ge=1, description="Miss causes: fewer masks than this on a part = never masked in enough views.")
    cause_view_precision: float = Field(0.5, ge=0, le=1, description="Miss causes: a mask is on a part if this share of its faces is the part's ...")
    cause_view_coverage: float = Field(0.2, ge=0, le=1, description="... and it covers this share of the part's seen faces.")
    cause_stage_iou: float = Field(0.5, ge=0, le=1, description="Miss causes: a stage keeps a part if one of its outputs has this face IoU with the part's seen faces.")
    cause_oe_deg: float = Field(2.0, ge=0, description="Joint causes: axis errors above this (deg) get a cause.")
    cause_md_m: float = Field(0.05, ge=0, description="Joint causes: hinge-line distances above this (m) get a cause.")
