"""Candidate validation against the articulation predictor, the paper's refinement, and motion limits."""

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
    trim_to_prediction: bool = Field(True, description="Cut a validated candidate back to the part the predictor sees: faces "
                                                       "its top views show outside the predicted mask that covers the part "
                                                       "(more views outside than inside) go, when they are at least a tenth "
                                                       "of it (a drawer grown into the door below; beyond the paper).")
    sparse_end_density: float = Field(0.1, ge=0, le=1, description="The part's box ends where its surface does: along each "
                                                                   "front side, end bins (5 mm) holding less than this share of "
                                                                   "the median bin's area are cut off when they span at least "
                                                                   "sparse_end_min_m (a triangle bridging the seam to a "
                                                                   "neighbour; 0: the box holds every vertex, as the paper).")
    sparse_end_min_m: float = Field(0.02, gt=0, description="Shortest sparse end (m) that is cut off the part's box.")
    sliding_min_height_m: float = Field(0.3, ge=0, description="A 'sliding' prediction is kept only with its axis in the "
                                                              "front plane and on a front at least this tall (a lower "
                                                              "vertical front sliding sideways is a drawer front, which "
                                                              "is pulled out along its normal instead).")


class LimitConfig(StageConfig):
    """Motion limits (the paper leaves them open)."""

    revolute_max_deg: float = Field(110.0, gt=0, le=180, description="Cap on revolute opening angle.")
    revolute_step_deg: float = Field(5.0, gt=0, description="Coarsest turn between two samples of the sweep that searches the collision-free opening.")
    sweep_step_m: float = Field(0.004, gt=0, description="Finest sweep sample: the fastest point of a part moves this far (at most "
                                                         "half of collision_clearance_m - 2 mm, so a point lands inside the band where "
                                                         "it blocks, not on or in the obstacle); far from obstacles samples are coarser.")
    collision_clearance_m: float = Field(0.01, ge=0, description="Clearance kept from background/neighbours in the sweep.")
    revolute_min_deg: float = Field(15.0, ge=0, description="Minimum useful opening: a door whose sweep is blocked before it is "
                                                            "reported 'blocked' (it keeps its free range).")
    prismatic_margin_m: float = Field(0.02, ge=0, description="Prismatic limit = cavity depth (never more than the furniture's depth) - margin.")
    prismatic_min_m: float = Field(0.05, ge=0, description="Smallest prismatic travel written (never past the back of the cavity); "
                                                           "a drawer blocked before it is reported 'blocked'.")
    prismatic_max_m: float = Field(0.6, gt=0, description="Largest prismatic travel where the furniture's depth behind the front was "
                                                          "not measured (d_body): a ray through an unseen back to a far wall must not "
                                                          "give a drawer a metre of travel (furniture is rarely deeper than 0.65 m).")
