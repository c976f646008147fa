"""2D->3D fusion, top-k views, re-segmentation and movable-part clipping."""

from pydantic import Field

from ._base import StageConfig


class FusionConfig(StageConfig):
    """Multi-view 2D->3D fusion through a face co-occurrence graph and Louvain communities."""

    erode_px: int = Field(4, ge=0, description="Erode each mask by this many px before collecting faces (boundary bleed).")
    through_band_px: int = Field(9, ge=0, description="A mask's front plane is fitted to its pixels within this many px of its outline; pixels whose surface lies more than clip.keep_behind_m behind it are seen through the front (a glass pane the scan lacks) and not lifted (0: off).")
    min_cooccurrence: int = Field(3, ge=1, description="Edge in the face graph if a face pair co-occurs in >= this many masks.")
    max_pairs_per_mask: int = Field(20000, ge=1, description="Cap on sampled face pairs per mask (keeps cost linear).")
    resolutions: tuple[float, ...] = Field((0.5, 1.0, 5.0, 50.0, 500.0), description="Louvain resolutions swept.")
    min_community_faces: int = Field(10, ge=1, description="Keep communities with more faces than this.")
    decimate_faces: int | None = Field(80000, description="Fuse on a mesh decimated to this many faces (None: full mesh).")
    seed: int = Field(0, description="Seed for pair sampling and Louvain.")
    work_width: int | None = Field(320, ge=16, description="Render, lift and score views at this image width (None: the masks' own size).")
    weld_m: float = Field(0.005, ge=0, description="Vertices closer than this count as one for connectivity (scans may not be welded).")
    attach_m: float = Field(0.02, ge=0, description="Components this close to a part's largest component stay with it (handles on doors).")
    keep_share: float = Field(0.2, ge=0, le=1, description="A proposal or part is cut to its largest connected component, with the components within attach_m of it and those holding at least this share of its area (1: the largest alone), when the masks name the object they show (Mask2D.instance: the largest alone otherwise). A glass door's frame whose thin rails the scan or the fusion mesh broke is two stiles a pane apart, each about half the door.")
    max_anchors: int = Field(8, ge=1, description="Face graph: anchor faces sampled per mask (each lifted face is paired with them; enough to bridge gaps).")
    distinct_jaccard: float = Field(0.95, ge=0, le=1, description="A community found again at another resolution (face Jaccard above this) is merged into the first.")
    claimed_share: float = Field(0.8, ge=0, le=1, description="A proposal with more than this share of its faces in earlier candidates is not re-segmented (it would re-segment to them).")
    merge_instances: bool = Field(True, description="Candidates whose best views' masks show one perceived object (Mask2D.instance: a backend that renders each 3D front into every view) are one part, their faces joined: a front seen in pieces past chairs and tables, each view showing another piece, fused into pieces that each became a part (free-standing tuning 301: one false 0.8 x 1.5 m panel exported as three doors). Masks without an instance are not touched.")
    lid_claims_skirt: bool = Field(True, description="A lid's re-segmented and proposal faces that its clip to the top's plane left out (the lip and the side skirts hanging from the top) are the lid's: no other candidate is made of them. Off, the skirts' own proposals became flaps of their own beside the lid (free-standing tuning chest freezers: one lid exported as two or three parts).")
    duplicate_iou: float = Field(0.5, ge=0, le=1, description="Candidates of several resolutions: a later one with vertex IoU above this with a kept one is dropped ...")
    duplicate_contained: float = Field(0.8, ge=0, le=1, description="... as is one with more than this share of its vertices inside a kept one (a piece of it).")


class TopKConfig(StageConfig):
    """Choice of the best views per 3D proposal (occlusion-aware silhouettes)."""

    k: int = Field(5, ge=1, description="Number of views kept per proposal.")
    min_iou: float = Field(0.5, ge=0, le=1, description="A view counts if mask IoU with the rendered proposal > this.")
    good_iou: float = Field(0.8, ge=0, le=1, description="IoU of a 'good' view.")
    border_px: int = Field(20, ge=0, description="Skip masks touching the image border within this many px.")
    min_mask_px: int = Field(100, ge=0, description="Skip masks smaller than this.")
    min_view_cover: float = Field(0.5, ge=0, le=1, description="An inner mask is preferred to border masks only where its view "
                                                              "sees at least this share of the proposal's surface that the "
                                                              "best-seeing matching view sees (0: always, as before).")


class ClipConfig(StageConfig):
    """RANSAC plane clipping of whole-object meshes to the movable slab (handles kept)."""

    enabled: bool = Field(True, description="Clip segmented meshes to the front plane.")
    ransac_threshold_m: float = Field(0.02, gt=0, description="RANSAC inlier distance (m).")
    ransac_iterations: int = Field(1000, ge=1, description="RANSAC iterations.")
    ransac_max_points: int = Field(2000, ge=3, description="RANSAC runs on at most this many face centroids (random subset).")
    max_abs_nz: float = Field(0.7071, ge=0, le=1, description="Near-vertical points: |n_z| <= sin 45 deg.")
    keep_behind_m: float = Field(0.03, ge=0, description="Keep geometry up to this far behind the plane (slab thickness).")
    seed: int = Field(0, description="RANSAC seed.")
    lid_min_area_m2: float = Field(0.15, ge=0, description="A part whose upward faces seen from above cover at least this area (m^2) and lid_ratio times its camera-facing vertical area is a lid: clipped to a horizontal plane (0: fronts only).")
    lid_ratio: float = Field(3.0, gt=0, description="Upward against camera-facing vertical area that makes a part a lid.")
    lid_max_tilt_deg: float = Field(15.0, ge=0, le=45, description="A face within this angle of pointing up counts towards a lid's top.")
