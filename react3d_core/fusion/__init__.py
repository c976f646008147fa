"""Segmentation stage: multi-view 2D->3D mask fusion, top-k views, re-segmentation, clipping.

Each sub-step is callable on its own (the Prefect layer lifts frames as separate tasks):
``lift_masks`` (per frame) -> ``fuse_proposals`` -> ``select_top_views`` -> ``resegment`` ->
``clip_part``; ``segment_parts`` runs them all.
"""

from ..stage import StageSpec
from .clip import clip_part, ransac_plane
from .connectivity import largest_component, weld_labels
from .lift import FrameLift, fill_holes, lift_masks
from .proposals import FusionMesh, Proposal, fuse_proposals, prepare_fusion_mesh
from .reseg import point_prompts, resegment
from .segment import lift_frames, segment_parts
from .topk import select_top_views

STAGE_VERSION = "8"  # 2: a candidate carries its views' mask label (perception's tag); 3: an inner mask whose view sees little of the proposal does not outrank border masks (topk.min_view_cover); 4: pixels seen through the front are not lifted; 5: a lid is clipped to its top's horizontal plane; 6: the faces a lid's clip left out (its skirts) make no candidate of their own; 7: candidates showing one perceived object are one part (fusion.merge_instances)
STAGE = StageSpec("fusion", __name__, STAGE_VERSION, sections=("fusion", "topk", "clip"), upstream=("perception",))

__all__ = [
    "STAGE",
    "STAGE_VERSION",
    "FrameLift",
    "FusionMesh",
    "Proposal",
    "clip_part",
    "fill_holes",
    "fuse_proposals",
    "largest_component",
    "lift_frames",
    "lift_masks",
    "point_prompts",
    "prepare_fusion_mesh",
    "ransac_plane",
    "resegment",
    "segment_parts",
    "select_top_views",
    "weld_labels",
]
