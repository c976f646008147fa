"""Hidden geometry behind a movable part."""

from pydantic import Field

from ._base import StageConfig


class CavityConfig(StageConfig):
    """Hidden geometry behind a movable part (d_in = min(d_image, d_hit, d_mesh, d_body))."""

    ignore_hits_thickness_factor: float = Field(2.0, ge=0, description="Ignore scene hits closer than this x part thickness.")
    search_radius_factor: float = Field(0.1, ge=0, description="Probe radius = factor x longest OBB edge.")
    wall_factor: float = Field(0.03, gt=0, description="Wall thickness = factor x shortest front edge.")
    min_wall_m: float = Field(0.008, gt=0, description="Minimum wall thickness (m).")
    default_depth_m: float = Field(0.5, gt=0, description="Depth used when no bound is available.")
    max_depth_m: float = Field(1.2, gt=0, description="A bound farther than this is none (the rays left the part's body, its back never scanned, and met the room wall or a unit across the room): the cavity takes default_depth_m (source 'beyond_max'). Clamped to it before, a drawer's carcass reached across the room into the swing of the doors facing it.")
    body_step_m: float = Field(0.02, gt=0, description="d_body: depth step of the up-ray profile behind the front (at most prismatic_margin_m keeps travel inside the body).")
    body_jump_m: float = Field(0.15, gt=0, description="d_body: an up-ray this much farther than inside the carcass (or missing) is past the furniture's back.")
    body_lateral_factor: float = Field(0.3, ge=0, le=0.5, description="d_body: up-rays at 0 and +-factor x the front's width from its centre (median).")
    body_floor_m: float = Field(0.05, ge=0, description="d_body: down-rays (where nothing is above the part) count only where they hit "
                                                        "this far above the scan's lowest point (a bottom board, not the floor, "
                                                        "whose scan ends somewhere under the furniture).")
    body_side_reach_m: float = Field(0.1, ge=0, description="d_body, where neither the up- nor the down-rays end: sideways rays "
                                                           "count only if they hit a side panel within half the front's width "
                                                           "+ this (the part's own carcass, not a neighbour or the room).")
    level_within_deg: float = Field(10.0, ge=0, le=45, description="A carcass behind a front whose normal is within this angle (degrees) "
                                                                   "of horizontal (or vertical) is built level: a front estimated a degree "
                                                                   "off plumb must not tilt the cavity's floor towards the room.")
