"""Hidden geometry behind a movable part: cavity depth d_in = min(d_image, d_hit, d_mesh, d_body), the base

The stage lives in :mod:`.estimate`; this package names it and its version."""

from .estimate import PartFrame, UP, base_mesh, d_body, d_hit, d_image, d_mesh, estimate_cavity, inner_box_mesh, wall_thickness

STAGE_VERSION = "4"  # 3: d_body bounds the cavity by the furniture's own depth; 4: down-rays where nothing is above

__all__ = ['PartFrame', 'STAGE_VERSION', 'UP', 'base_mesh', 'd_body', 'd_hit', 'd_image', 'd_mesh', 'estimate_cavity', 'inner_box_mesh', 'wall_thickness']
