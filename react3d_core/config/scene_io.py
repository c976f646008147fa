"""Which frames of a capture are used."""

from pydantic import Field

from ._base import StageConfig


class MissedSurfaceConfig(StageConfig):
    """Slabs over vertical surfaces the depth sensor missed (dark, glossy fronts): voxels seen through pixels
    with neither scan surface nor depth reading, and never seen through to a surface, form the missed
    volumes; their vertical faces towards the cameras become flat coloured slabs appended to the mesh
    (react3d_core/scene_io/missed_surface.py)."""

    enabled: bool = Field(True, description="Add slabs over vertical surfaces the sensor missed before any stage runs.")
    min_hole_share: float = Field(0.08, ge=0, le=1, description="Skip the carving (a cost saver: up to a minute on a large kitchen) when the views' pixels without a depth reading are under this share on average: 0.03-0.06 on clean and TSDF held-apart scenes, whose sensors miss nothing, 0.40 on dark tuning 340.")
    voxel_m: float = Field(0.03, gt=0, description="Side of the carving voxels (m).")
    work_width: int = Field(160, ge=16, description="Width (px) of the renders and depth maps the carving reads.")
    max_views: int = Field(24, ge=1, description="At most this many views (evenly chosen) carve and colour.")
    min_views: int = Field(3, ge=1, description="A missed voxel is seen through hole pixels in at least this many views.")
    max_free: int = Field(1, ge=0, description="...and seen in front of a scan surface or depth reading in at most this many.")
    margin_m: float = Field(0.04, ge=0, description="A voxel is in front of a surface only when closer by more than this (m).")
    near_m: float = Field(0.1, gt=0, description="Voxels closer to a camera than this (m) are not judged by it.")
    min_area: float = Field(0.06, gt=0, description="Smallest missed vertical surface kept (m²): about a small drawer front.")
    min_depth_m: float = Field(0.06, gt=0, description="A missed volume holds at least min_area x this (m³): thinner ones are noise.")
    min_returns: int = Field(15, ge=3, description="A missed vertical plane is fixed by at least this many scan vertices on it (its sparse returns).")
    max_island_m2: float = Field(0.1, gt=0, description="Returns are vertices of scan pieces under this area (m²): a missed front keeps islands, walls and floors are large.")
    flat_island_nz: float = Field(1.0, ge=0, le=1, description="Opt-in (0.8 to turn it on; 1: off). Islands facing up or down (the area-weighted mean of their faces' normals has a vertical part of at least this) are no returns of a vertical front: a dark worktop's returns lie all over it, and a vertical plane drawn diagonally through them gathered more returns than the fronts below it (dark tuning 350: a base run's slab turned 11 degrees through the cabinets). With pair_reach_m 0.6: both dark tuning sets 0.568 -> 0.589 at front level, but held-apart dark 0.448 -> 0.387 (fewer slabs, fewer fronts), so off.")
    min_spread_m: float = Field(0.1, gt=0, description="A plane's returns spread over at least this (m, 10th-90th percentile) across and up.")
    min_line_m: float = Field(0.3, ge=0, description="Returns on a vertical plane that run at least this far (m) across but under min_spread_m up, a horizontal line, fix a plane too; its region is the missed volume's section the line touches, up and down, within return_reach_m across. A black base run may return only its top edge or the edge of a dark worktop over it (dark tuning 350: a 2 cm line at 0.88 m, 590 returns, and no slab over the nine fronts below). Both dark tuning sets, full bench: F1@0.5 0.579 -> 0.596 (216 -> 229 found); scans whose views miss under min_hole_share are never carved. 0: off.")
    line_clear_m: float = Field(0.1, gt=0, description="A line of returns (min_line_m) is an edge only when at most line_ahead_share as many returns lie from line_gap_m up to this far (m) in front of it, at its height and along it: a vertical plane cuts a strip out of a dark worktop's or floor's returns at any angle (dark tuning 343: 17 lines turned every way through a worktop), while a worktop's front edge has nothing in front of it.")
    line_gap_m: float = Field(0.05, ge=0, description="... (see line_clear_m): the densest strip a plane's tolerance holds lies up to this far (m) behind the edge of a sheet of returns (dark tuning 340: 3 cm behind a worktop's front edge).")
    line_ahead_share: float = Field(0.2, ge=0, description="... at most this share of the line's returns (see line_clear_m).")
    line_fill: float = Field(0.5, ge=0, le=1, description="A line of returns holds a return in at least this share of its voxel_m steps along its length: speckle on a dark floor does not (dark tuning 340: floor lines fill 0.1-0.43, a base run's top edge 0.96).")
    line_axis_deg: float = Field(5.0, ge=0, le=45, description="A line of returns runs along the room's walls (the azimuth of the scan's large vertical faces, modulo 90 degrees) within this angle (degrees): a dark worktop's returns hold strips at any angle whose front side is bare near the worktop's corners (dark tuning 343: lines turned 31 and 17 degrees).")
    plane_tol_m: float = Field(0.015, gt=0, description="A return lies on a plane within this distance (m).")
    ransac_iters: int = Field(400, ge=1, description="RANSAC hypotheses per vertical plane.")
    refits: int = Field(3, ge=0, description="Times the best plane is refitted to its inliers (least squares).")
    ransac_neighbours: int = Field(24, ge=2, description="With pair_reach_m 0: a hypothesis pairs a return with one of its this many nearest returns.")
    pair_reach_m: float = Field(0.0, ge=0, description="Opt-in (0.6 to turn it on). A hypothesis pairs a return with any return within this horizontal distance (m; pairs closer than a voxel are dropped). A dark front's returns come in vertical columns (door edges, handles): its nearest returns all lie in its own column, their pairs point anywhere, and a plane turned 5 degrees through one column outscored the wall run it belongs to (dark tuning 357). Measured with flat_island_nz (see there). 0: the nearest ransac_neighbours.")
    min_camera_share: float = Field(0.3, ge=0, le=1, description="A face is kept when at least this share of the views stands in front of it.")
    return_reach_m: float = Field(0.4, gt=0, description="A plane's missed region reaches this far (m) from its returns: the sparse returns of a dark front lie all over it.")
    max_scanned: float = Field(0.5, ge=0, le=1, description="A plane whose returns already cover more than this share of its region is scanned, not missed.")
    merge_deg: float = Field(10.0, ge=0, le=90, description="Planes facing the same way within this angle may be layers of one surface.")
    merge_m: float = Field(0.15, ge=0, description="...when their overlapping regions lie within this distance (m): the one with most returns is kept.")
    layer_deg: float = Field(30.0, ge=0, le=90, description="A plane facing within this angle of one with more returns ...")
    layer_share: float = Field(0.8, ge=0, le=1, description="... at least this share of whose returns lie within merge_m of that plane and over its region is a layer of it (handles, stray returns) and is dropped: a line through a column of handle returns and a few stray ones is turned by several degrees, and its slab, far from the front's plane, was cut into false fronts (dark tuning front level, F1@0.5 0.559 -> 0.573; 0: off).")
    res_m: float = Field(0.015, gt=0, description="Cell size of the slab raster (m).")
    close_m: float = Field(0.07, ge=0, description="Gaps up to this (m) in a plane's region are closed.")
    seed: int = Field(0, description="RANSAC seed (deterministic).")



class FrameSelectionConfig(StageConfig):
    """Frame selection. Default (``stride`` None): keyframes by what the views add — camera motion since
    the last kept frame, then new or under-observed surface in a low-resolution face-id buffer — capped
    at ``keyframe_cap``. A fixed stride suits one frame rate only (stride 5 kept 12 of a sparse
    60-frame capture); an explicit ``stride`` is still honoured as given."""

    stride: int | None = Field(None, ge=1, description="Use every n-th frame; None selects keyframes by motion and coverage.")
    max_frames: int | None = Field(None, ge=1, description="Explicit cap on the number of frames (evenly subsampled), any mode.")
    keyframes: bool = Field(False, description="With an explicit stride: also keep a frame only when the camera moved/turned enough since the last kept one.")
    keyframe_translation_m: float = Field(0.05, gt=0, description="Keyframe: minimum camera translation since the last kept frame (m).")
    keyframe_rotation_deg: float = Field(3.0, gt=0, description="Keyframe: minimum camera rotation since the last kept frame (deg).")
    keyframe_cap: int = Field(300, ge=1, description="Keyframe mode: at most this many frames (evenly subsampled from the keyframes).")
    coverage_width: int = Field(64, ge=0, description="Keyframe mode: width (px) of the face-id buffer used to measure what a view adds; 0 = motion only.")
    coverage_target_views: int = Field(10, ge=1, description="Keyframe mode: surface seen in this many kept frames counts as covered.")
    coverage_voxel_m: float = Field(0.05, gt=0, description="Keyframe mode: surface is counted per voxel of this side (m) when measuring what a view adds (about one coverage-buffer pixel at 2 m).")
    coverage_min_new: float = Field(0.05, ge=0, le=1, description="Keyframe mode: keep a moved frame only if at least this fraction of its surface pixels is not yet covered.")
    image_width: int = Field(960, ge=32, description="RGB working width; the reference worked at 960x720. K is rescaled with it.")
    missed_surface: MissedSurfaceConfig = Field(default_factory=MissedSurfaceConfig, description="Slabs over vertical surfaces the depth sensor missed (dark, glossy fronts).")
