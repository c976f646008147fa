"""Duplicate part removal."""

from pydantic import Field

from ._base import StageConfig


class DedupConfig(StageConfig):
    """Duplicate removal: overlapping, merged, fragment, sliver and same-motion pieces."""

    tau_dup: float = Field(0.5, ge=0, le=1, description="Stage 1: pairwise IoU >= this -> keep the larger part.")
    tau_low: float = Field(0.2, ge=0, le=1, description="Stage 2: smaller parts with IoU >= this are cover candidates.")
    cover_iou: float = Field(0.8, ge=0, le=1, description="Stage 2: remove a part whose candidates' union reaches this IoU.")
    max_candidates: int = Field(16, ge=1, description="Stage 2 bound: consider at most this many candidates per part.")
    tau_contained: float = Field(0.7, ge=0, le=1, description="Stage 3: remove a part with this share of its vertices inside one larger kept part (a fragment).")
    fragment_share: float = Field(0.25, ge=0, le=1, description="Stage 4: a part at most this share of a larger kept part's size (vertices) ...")
    footprint_margin_m: float = Field(0.01, ge=0, description="... with tau_contained of its points inside that part's box grown by this (m) is a sliver of it.")
    motion_share: float = Field(0.5, ge=0, le=1, description="Stage 5: a smaller part with this share of its front's footprint inside a larger kept part's front (in its slab) that moves the same way is a piece of it and merged into it.")
    motion_angle_deg: float = Field(10.0, ge=0, le=90, description="Stage 5: same motion = same joint type with axes and front normals within this angle (degrees) ...")
    motion_hinge_m: float = Field(0.05, ge=0, description="... and, for hinges, axis lines within this distance (m): a piece's hinge is estimated from its own box, a few cm off its door's.")
    motion_slab_m: float = Field(0.03, ge=0, description="Stage 5: the footprint counts only within this distance (m) of the larger part's slab along its normal.")
    enclosed_share: float = Field(0.8, ge=0, le=1, description="Stage 6: a kept part with this share of its front's footprint inside a larger kept part's box (in its slab) is enclosed by it ...")
    enclosed_fill_max: float = Field(0.5, ge=0, le=1, description="... and when the larger part's surface (less what the two share) covers the enclosed footprint at most this share as densely as the rest of its box, the larger part is a mask merged around it: its box and faces are cut back to the side of the enclosed part that keeps most of its surface.")
    bridge_share: float = Field(0.8, ge=0, le=1, description="Stage 3: a part with this share of its vertices inside other kept parts, split over at least two of them (each holding tau_low of it or more), is a mask bridging their fronts: removed.")
    scrap_max_m: float = Field(0.08, ge=0, description="Stage 5: a part whose front's shorter side is under this (m) is no front (the smallest a home holds is ~10 cm) ...")
    scrap_reach_m: float = Field(0.06, ge=0, description="... and with tau_contained of its points within this (m) of a larger kept part's front footprint, in its slab, a scrap of it: merged into it whatever motion its few points suggest.")
