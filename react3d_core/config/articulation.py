"""Candidate validation, refinement, motion limits, cavity, dedup and assembly thresholds."""

from pydantic import Field

from ._base import StageConfig


class ArticulationConfig(StageConfig):
    """Validation of candidates against the articulation predictor, and refinement (paper eqs.)."""

    valid_iou: float = Field(0.6, ge=0, le=1, description="Candidate valid if predictor mask IoU >= this in a top-k view.")
    refine: bool = Field(True, description="Snap axes/origins to the part's OBB (off for the ablation).")
    flat_ratio: float = Field(0.5, gt=0, le=1, description="Refine only flat parts: shortest OBB side < ratio x second.")
    consensus_views: bool = Field(True, description="Initial joint from every top view whose prediction matches the part "
                                                    "(median origin, mean axis) instead of the single best view (the paper): "
                                                    "one view's origin error no longer hinges a door on the wrong edge.")
    upright_tolerance: float = Field(0.1, ge=0, description="A vertical front keeps a gravity-aligned box unless the "
                                                            "minimal box is smaller by more than this share of its "
                                                            "volume (0: always the minimal box, as the paper).")


class LimitConfig(StageConfig):
    """Motion limits (the paper leaves them open)."""

    revolute_max_deg: float = Field(110.0, gt=0, le=180, description="Cap on revolute opening angle.")
    revolute_step_deg: float = Field(5.0, gt=0, description="Sweep step when searching the collision-free opening.")
    collision_clearance_m: float = Field(0.01, ge=0, description="Clearance kept from background/neighbours in the sweep.")
    prismatic_margin_m: float = Field(0.02, ge=0, description="Prismatic limit = cavity depth - margin.")
    prismatic_min_m: float = Field(0.05, ge=0, description="Smallest prismatic travel written.")


class CavityConfig(StageConfig):
    """Hidden geometry behind a movable part (d_in = min(d_image, d_hit, d_mesh, d_body))."""

    ignore_hits_thickness_factor: float = Field(2.0, ge=0, description="Ignore scene hits closer than this x part thickness.")
    search_radius_factor: float = Field(0.1, ge=0, description="Probe radius = factor x longest OBB edge.")
    wall_factor: float = Field(0.03, gt=0, description="Wall thickness = factor x shortest front edge.")
    min_wall_m: float = Field(0.008, gt=0, description="Minimum wall thickness (m).")
    default_depth_m: float = Field(0.5, gt=0, description="Depth used when no bound is available.")
    max_depth_m: float = Field(1.2, gt=0, description="Upper clamp on cavity depth.")
    body_step_m: float = Field(0.02, gt=0, description="d_body: depth step of the up-ray profile behind the front (at most prismatic_margin_m keeps travel inside the body).")
    body_jump_m: float = Field(0.15, gt=0, description="d_body: an up-ray this much farther than inside the carcass (or missing) is past the furniture's back.")
    body_lateral_factor: float = Field(0.3, ge=0, le=0.5, description="d_body: up-rays at 0 and +-factor x the front's width from its centre (median).")


class DedupConfig(StageConfig):
    """Two-stage duplicate removal."""

    tau_dup: float = Field(0.5, ge=0, le=1, description="Stage 1: pairwise IoU >= this -> keep the larger part.")
    tau_low: float = Field(0.2, ge=0, le=1, description="Stage 2: smaller parts with IoU >= this are cover candidates.")
    cover_iou: float = Field(0.8, ge=0, le=1, description="Stage 2: remove a part whose candidates' union reaches this IoU.")
    max_candidates: int = Field(16, ge=1, description="Stage 2 bound: consider at most this many candidates per part.")
    tau_contained: float = Field(0.7, ge=0, le=1, description="Stage 3: remove a part with this share of its vertices inside one larger kept part (a fragment).")
    fragment_share: float = Field(0.25, ge=0, le=1, description="Stage 4: a part at most this share of a larger kept part's size (vertices) ...")
    footprint_margin_m: float = Field(0.01, ge=0, description="... with tau_contained of its points inside that part's box grown by this (m) is a sliver of it.")


class AssemblyConfig(StageConfig):
    """Carving the background."""

    obb_margin_m: float = Field(0.005, ge=0, description="Grow part OBBs by this before deleting background vertices.")
