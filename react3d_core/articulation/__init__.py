"""Articulation stage: validate a candidate against the predictor, lift its joint, refine it on the OBB.

The stage lives in :mod:`.candidate`; this package names it and its version."""

from ..stage import StageSpec
from .candidate import ArticulatedPart, PartFit, articulate_candidate, fit_part, min_obb, refine_articulation

STAGE_VERSION = "8"  # 3: sliding (in-plane prismatic) predictions keep an in-plane axis; 4: consensus of the top views, upright boxes for vertical fronts; 5: sliding kept only where the geometry agrees (axis in the front plane, not a drawer front); 6: a validated candidate is trimmed back to the predicted part (trim_to_prediction); 7: the trim follows the part through views that show none of its core; 8: the box ends where the surface does along the front sides, and stays upright along a vertical clipping plane
STAGE = StageSpec("articulation", __name__, STAGE_VERSION, sections=("articulation",), upstream=("fusion",))

__all__ = ["STAGE", "STAGE_VERSION", "ArticulatedPart", "PartFit", "articulate_candidate", "fit_part", "min_obb", "refine_articulation"]
