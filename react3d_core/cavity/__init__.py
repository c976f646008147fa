"""Hidden geometry behind a movable part: cavity depth d_in = min(d_image, d_hit, d_mesh, d_body), the base

The stage lives in :mod:`.estimate`; this package names it and its version."""

from ..stage import StageSpec
from .estimate import PartFrame, UP, base_mesh, d_body, d_hit, d_image, d_mesh, estimate_cavity, inner_box_mesh, wall_thickness

STAGE_VERSION = "7"  # 3: d_body bounds the cavity by the furniture's own depth; 4: down-rays where nothing is above; 5: down-rays only above the floor, side panels where neither ends; 6: carcasses built level; 7: a bound past max_depth_m is none (default depth)
STAGE = StageSpec("cavity", __name__, STAGE_VERSION, sections=("cavity",), upstream=("articulation",))

__all__ = ["STAGE", "PartFrame", "STAGE_VERSION", "UP", "base_mesh", "d_body", "d_hit", "d_image", "d_mesh", "estimate_cavity", "inner_box_mesh", "wall_thickness"]
