"""Perception backends and their thresholds (tags, 2D masks, point prompts, articulation predictor)."""

import re
from typing import Literal
from urllib.parse import parse_qsl, urlsplit

from pydantic import Field, ValidationInfo, field_validator

from ..errors import ConfigError
from ._base import StageConfig


class OracleNoiseConfig(StageConfig):
    """Realism of the oracle backend (ground-truth masks/articulations made imperfect on purpose)."""

    boundary_px: int = Field(2, description="Erode (<0) or dilate (>0) GT masks by this many pixels at 960 px width.")
    handle_holes: bool = Field(False, description="Remove handle pixels from part masks (like Grounded-SAM missing handles).")
    drop_rate: float = Field(0.1, ge=0, le=1, description="Probability that a visible part is not detected in a frame.")
    merge_rate: float = Field(0.0, ge=0, le=1, description="Probability that two adjacent parts come out as one mask.")
    whole_object_rate: float = Field(0.0, ge=0, le=1, description="Probability that a mask covers the whole object (part + frame).")
    false_positive_rate: float = Field(0.0, ge=0, description="Expected false-positive masks per frame.")
    min_visible_px: int = Field(100, ge=0, description="Parts with fewer visible pixels in a frame are not reported.")
    axis_noise_deg: float = Field(7.0, ge=0, description="Std-dev-like angular noise on initial axes (OPDMulti-like: ~7 deg).")
    origin_noise_m: float = Field(0.2, ge=0, description="Positional noise on initial origins (OPDMulti-like: ~0.2 m).")
    type_flip_rate: float = Field(0.0, ge=0, le=1, description="Probability that the initial joint type is wrong.")
    seed: int = Field(0, description="Seed of the oracle's noise.")


class FrontRulesConfig(StageConfig):
    """The heuristic's front rules on the scan mesh (perception/heuristic/fronts.py): which planar
    facets are openable fronts, their handles and frames, and the joint guessed from shape and handle."""

    min_w: float = Field(0.12, gt=0, description="Narrowest front (m).")
    max_w: float = Field(1.3, gt=0, description="Widest front (m).")
    min_h: float = Field(0.1, gt=0, description="Lowest front (m).")
    max_h: float = Field(2.3, gt=0, description="Tallest front (m).")
    max_tilt: float = Field(0.25, ge=0, le=1, description="A front is vertical: |n_z| of its normal at most this (also bounds the image path's planes).")
    min_fill: float = Field(0.8, ge=0, le=1, description="A front's facet fills at least this share of its bounding rectangle.")
    handle_max_area: float = Field(0.03, gt=0, description="Largest handle facet (m^2); also the largest rim/bevel facet added to a front.")
    handle_depth: tuple[float, float] = Field((0.002, 0.09), description="Handle facets stand this far in front of the front's plane (min, max; m).")
    drawer_max_h: float = Field(0.45, gt=0, description="Drawers are at most this tall (m): deep drawers reach ~0.45 m, oven/dishwasher doors are >= 0.5 m.")
    flap_min_top: float = Field(1.2, ge=0, description="A top-hinged flap lifts upwards: its top is above this height (m, z up from the floor), above a worktop.")
    neighbour_gap: float = Field(0.03, ge=0, description="Coplanar fronts closer than this (m) are neighbours (door pairs, drawer stacks).")
    frame_max_width: float = Field(0.2, ge=0, description="Widest stile/rail of a frame-and-panel front (m).")
    frame_depth: tuple[float, float] = Field((0.001, 0.03), description="Frame pieces stand this far proud of a recessed panel (min, max; m) ...")
    raised_depth: tuple[float, float] = Field((-0.016, -0.003), description="... or a raised panel stands this far proud of them (min, max; m, negative: frame behind the panel).")
    rim_depth: float = Field(0.03, ge=0, description="A front's edge/bevel facets reach this far behind its plane (m) ...")
    rim_margin: float = Field(0.02, ge=0, description="... and this far outside its rectangle (chamfered edges; m).")


class HeuristicConfig(StageConfig):
    """The weight-free heuristic: planar facets and fronts on the scan mesh, per-frame renders, and the
    image path (fronts found in the colour frames: seams, handles) and sliding-door pairs."""

    fronts: FrontRulesConfig = Field(default_factory=FrontRulesConfig, description="Front rules on the scan mesh.")
    facet_weld_m: float = Field(0.001, gt=0, description="Planar facets: vertices closer than this (m) are merged before joining faces.")
    facet_max_angle_deg: float = Field(12.0, ge=0, le=180, description="Planar facets: faces sharing an edge join when their normals differ by at most this (deg).")
    render_scale: float = Field(0.5, gt=0, le=1, description="Per-frame front renders at this fraction of the colour size (upsampled).")
    n_probe: int = Field(24, ge=1, description="Frames (evenly spread) rendered at quarter size to find which facets the cameras see.")
    probe_view_px: int = Field(4, ge=1, description="A facet counts as seen in a probe view with at least this many pixels ...")
    probe_min_views: int = Field(2, ge=1, description="... and is visible when seen in this many probe views ...")
    probe_min_px: int = Field(40, ge=0, description="... with at least this many pixels over all probe views.")
    min_mask_px: int = Field(150, ge=0, description="A front yields a mask in a frame when it covers at least this many pixels there.")

    # image path: fronts in the colour frames
    image_fronts: bool = Field(True, description="Also find fronts in the colour frames (real scans have no seams in the mesh).")
    ortho_resolution: float = Field(0.004, gt=0, description="Metres per pixel of the fused plane orthophotos.")
    max_views: int = Field(30, ge=1, description="Views fused per plane, best first.")
    calibrate_colour: bool = Field(True, description="Self-calibrate colour focal scale / principal point against the mesh (unregistered RGB-D).")
    seam_contrast: float = Field(0.01, ge=0, description="A seam pixel is this much darker than both sides (fraction of the plane's mean).")
    seam_span: float = Field(0.35, ge=0, le=1, description="A seam covers this fraction of the cell it splits.")
    seam_prominence: float = Field(0.3, ge=0, le=1, description="... and this much more than the lines around it (vertical seams).")
    seam_prominence_h: float = Field(0.5, ge=0, le=1, description="The same for horizontal seams (reflections of table/shelf edges are horizontal).")
    seam_z: float = Field(15.0, ge=0, description="A straight seam: the line's median brightness dips this many noise units below the lines beside it (found through wood grain).")
    step_contrast: float = Field(0.25, ge=0, description="A colour step along a whole line (a door leaf in a pale wall) cuts when its colour distance is at least this ...")
    step_z: float = Field(15.0, ge=0, description="... and this many noise units of the cell's steps.")
    handle_contrast: float = Field(0.12, ge=0, description="Colour distance of handle pixels from the local background.")
    handle_len: tuple[float, float] = Field((0.1, 0.5), description="Long side of a handle (m).")
    handle_thick: tuple[float, float] = Field((0.014, 0.07), description="Short side of a handle (m).")
    plain_floor_gap: float = Field(0.03, ge=0, description="Image path: a handle-less front whose bottom edge is this close to the floor (m) is a piece of wall (base units stand on a plinth; room doors have handles); 0: no floor rule.")
    floor_min_area: float = Field(0.5, ge=0, description="Image path: the floor is the lowest 2 cm band of upward-facing mesh holding at least this area (m^2), at its area-weighted median height; no such band: no floor rule.")
    handleless_min_seams: int = Field(2, ge=0, description="A handle-less cell cut out by this many straight seams (push-to-open fronts) is a front; 0: only beside a handled front.")
    clutter_cell_median: bool = Field(True, description="Image cells: a pixel is clutter only when it is also off the cell's own median colour (a band along an edge shared with a front of another colour is not).")
    step_over_dip: bool = Field(True, description="Image cells: a colour step along the whole cell that is stronger than the best dark line is the cut (a shaker frame casts a dark line inside its own edge).")
    clutter_line_min_len: float = Field(0.15, ge=0, description="Image cells: straight horizontal/vertical lines at least this long (m) are a front's structure (shaker frames, tile joints), not clutter; 0 counts them.")
    clutter_line_max_width: float = Field(0.02, ge=0, description="Image cells: ... and at most this thick (m).")
    splashback: bool = Field(True, description="Drop fronts standing on a worktop flush with the wall behind it (splash-back: tiles, sockets).")
    splashback_min_z: float = Field(0.5, ge=0, description="Splash-back: the worktop under the front's bottom edge is above this height (m).")
    splashback_band: float = Field(0.08, ge=0, description="Splash-back: the worktop is this close to the front's bottom edge in height (m).")
    splashback_reach: tuple[float, float] = Field((0.03, 0.33), description="Splash-back: the strip in front of the front examined for a worktop (m in front, from/to).")
    splashback_cover: float = Field(0.2, ge=0, le=1, description="Splash-back: share of that strip the worktop must cover.")
    room_wall: bool = Field(True, description="On the room's outer walls (planes with no scan surface behind them) keep only fronts shaped like room doors, typed as side-hinged doors (perception/heuristic/room_walls.py).")
    room_wall_behind_share: float = Field(0.005, ge=0, le=1, description="Outer wall: less than this share of the scan's surface area lies behind the front's plane ...")
    room_wall_depth: float = Field(0.1, ge=0, description="... more than this far (m) ...")
    room_wall_min_area: float = Field(1.0, ge=0, description="... and the plane holds at least this much other surface (m^2) outside every front (a lone cabinet scanned from the front has no wall).")
    room_door_min_h: float = Field(1.8, gt=0, description="Room door on an outer wall: at least this tall (m) ...")
    room_door_w: tuple[float, float] = Field((0.6, 1.3), description="... this wide (min, max; m) ...")
    room_door_floor_gap: float = Field(0.05, ge=0, description="... and its bottom edge this close to the floor (m).")
    drawer_max_top: float = Field(1.7, ge=0, description="A drawer's top edge is at most this high above the floor (m): nothing slides out above eye level; a drawer-typed strip higher up is dropped (perception/heuristic/reach.py); 0: no limit.")
    min_tile_side: float = Field(0.25, ge=0, description="Handle-less cells smaller than this both ways are tiles, not fronts (m).")
    sliding_track_offset: tuple[float, float] = Field((0.008, 0.06), description="Sliding doors: plane offset between two side-by-side fronts on two tracks (m).")
    sliding_max_overlap: float = Field(0.12, ge=0, description="Sliding doors: the two fronts' outlines overlap by at most this (m).")
    sliding_max_gap: float = Field(0.02, ge=0, description="Sliding doors: ... or leave at most this gap between them (m).")
    sliding_min_height_overlap: float = Field(0.9, ge=0, le=1, description="Sliding doors: share of the smaller height the two fronts share.")
    sliding_min_parallel: float = Field(0.97, ge=0, le=1, description="Sliding doors: |cos| between the two fronts' normals at least this.")
    plane_offset_tol: float = Field(0.025, ge=0, description="Image path: faces this close to a vertical plane belong to it (m).")
    plane_angle_tol_deg: float = Field(12.0, ge=0, description="Image path: faces whose normal is within this of a plane's belong to it (deg).")
    plane_refit_deg: float = Field(3.0, ge=0, description="Image path: a plane at least 1 m wide takes, within this of its normals' mean direction, the direction along which its faces' positions are sharpest (a curved appliance door skews the normals; deg, 0: off).")
    plane_refit_min_gain: float = Field(1.4, ge=1, description="Image path: ... only when the offsets are at least this many times sharper (integral of the squared density) than along the normals' direction.")
    min_plane_area: float = Field(0.08, ge=0, description="Image path: smallest vertical plane photographed (m^2; at least min_w x min_h).")
    plane_cell: float = Field(0.04, gt=0, description="Image path: pieces of one plane farther apart than this are separate planes (m).")
    plane_min_fragment_area: float = Field(0.03, ge=0, description="Image path: fragments of a plane's coverage smaller than this are not part of it (m^2).")
    face_depth: tuple[float, float] = Field((-0.02, 0.07), description="Image path: faces this far behind/in front of the plane are taken into a front (m).")
    outline_fill_px: int = Field(20, ge=0, description="Image path: holes and notches up to this many orthophoto px wide are inside a plane's outline (handle shadows).")
    protrusion_depth: tuple[float, float] = Field((0.012, 0.09), description="Image path: mesh faces this far in front of the plane mark handles (m).")
    protrusion_from_surface: bool = Field(True, description="Image path: mesh handles stand protrusion_depth in front of the surface around them (median offset of the faces within handle_background_win) instead of in front of the fitted plane, so a TSDF wall's bumps off its plane are no handles (heuristic version 14, with handle_side_cover). Tuning scenes, front F1: TSDF 0.801 -> 0.812, laser 0.826 -> 0.834 (docs/perception.md).")
    ortho_max_side_px: int = Field(1200, ge=1, description="Orthophotos of very large planes get a coarser grid, at most this many px a side.")
    ortho_min_cos: float = Field(0.3, ge=0, le=1, description="Orthophotos: views more grazing than this cos to the plane are not used.")
    ortho_render_scale: float = Field(0.5, gt=0, le=1, description="Orthophotos: face-id buffer size relative to the colour image.")
    ortho_erode_px: int = Field(3, ge=0, description="Orthophotos: depth-buffer pixels kept this far from depth jumps (occluder outlines).")
    ortho_edge_jump: float = Field(0.05, gt=0, description="Orthophotos: a depth jump between neighbouring pixels marking an outline (m).")
    ortho_depth_tol: float = Field(0.03, ge=0, description="Orthophotos: a plane point is seen when the scan is within this (m, +1 % of the distance).")
    ortho_margin: float = Field(0.02, ge=0, description="Orthophotos: grid margin around a plane's extent (m).")
    calib_scale_range: tuple[float, float] = Field((0.84, 1.12), description="Colour calibration: focal scales searched.")
    calib_shift_range_px: float = Field(16.0, ge=0, description="Colour calibration: principal-point shifts searched (px at 640 px width).")
    calib_min_gain: float = Field(0.2, ge=0, le=1, description="Colour calibration: used only when it cuts the disagreement by this fraction.")
    register_sigmas_px: tuple[float, ...] = Field((), description="Per-view colour registration, opt-in: image blur per coarse-to-fine level (px at 640 px width), e.g. [12, 6, 3, 1.5]; () = off. For RGB-D whose colour is not synchronised with depth (docs/perception.md: what it gains and costs).")
    register_prior_scale: float = Field(0.08, gt=0, description="Per-view colour registration: prior std of a view's focal scale and aspect around the scene calibration.")
    register_prior_shift_px: float = Field(30.0, gt=0, description="Per-view colour registration: prior std of a view's shift (px at 640 px width).")
    min_front_side: float = Field(0.1, ge=0, description="Image cells: no cell narrower than this (m).")
    handle_aspect: float = Field(2.2, ge=1, description="Image handles: long side at least this times the short side.")
    handle_background_win: float = Field(0.12, gt=0, description="Image handles: window of the local background — of the colour, and of the surface a handle in the mesh stands out from (m).")
    cell_min_seen: float = Field(0.55, ge=0, le=1, description="Image cells: share of a cell the plane's faces must cover.")
    max_clutter: float = Field(0.18, ge=0, le=1, description="Image cells: share of a cell's pixels off its local background above which it is clutter (posters, tiles, shelves).")
    max_clutter_handle: float = Field(0.3, ge=0, le=1, description="Image cells: the same share for a cell holding a handle (raised-panel doors shade their own faces; a handle is evidence of a front); never below max_clutter.")
    handle_side_cover: float = Field(0.4, ge=0, le=1, description="Image handles: the plane's outline covers at least this share of the 2 cm band on each long side of a handle (out of the grid counts as uncovered): a handle sits on a front, a ridge at the plane's end (a wall corner, a unit's side) has the plane on one side only (RedKitchen: a door made from a ridge at the tiled wall's end). 0: off.")
    handle_outline_margin: float = Field(0.02, ge=0, description="Image handles: colour blobs this close to the plane's outline are not handles (m).")
    handle_shadows: bool = Field(True, description="Image handles: on a front without a seen handle, an enclosed horizontal unseen hole of handle size above the cameras' median height is the handle's scanning shadow (a bar seen from below hides the front behind it in every view); it types the joint (wall-cabinet flaps), it does not cut cells.")
    texture_factor: float = Field(3.0, ge=0, description="Image path: handle/seam thresholds rise to this many times the plane's median response (textured planes).")
    max_split_depth: int = Field(6, ge=0, description="Image cells: guillotine split recursion depth.")
    outline_step: float = Field(0.5, ge=0, description="Image cells: where the covered extent across a line jumps by this share of the cell (an L-shaped outline: a tall unit beside a base run), the cell is cut there first; 0: off.")


class PerceptionConfig(StageConfig):
    """Which backend runs each model call, and the paper's thresholds."""

    backend: Literal["heuristic", "oracle", "models"] = Field(
        "heuristic", description="heuristic: weight-free RGB-D; oracle: ground truth (+noise); models: foundation models."
    )
    box_threshold: float = Field(0.3, ge=0, le=1, description="Grounding DINO box threshold (paper: 0.3).")
    text_threshold: float = Field(0.25, ge=0, le=1, description="Grounding DINO text threshold (paper: 0.25).")
    always_keep_tags: tuple[str, ...] = Field(("door",), description="Tags kept whatever the tag filter says.")
    prompt_suffix: str = Field(" door", description="Phrase for openable tags, e.g. 'cabinet' -> 'cabinet door'.")
    hole_close_px: int = Field(30, ge=0, description="Closing kernel (px at 960x720) that fills missed handles in masks.")
    detector_model: str = Field("IDEA-Research/grounding-dino-tiny", description="Open-vocabulary detector (hub id or local path).")
    sam_model: str = Field("facebook/sam-vit-huge", description="SAM (hub id or local path).")
    tagger_model: str = Field("xinyu1205/recognize-anything-plus-model", description="Image tagger (RAM++ or alternative).")
    tag_filter_endpoint: str | None = Field(None, description="OpenAI-compatible chat endpoint for the openable-tag filter.")
    tag_filter_model: str = Field("llava-hf/llava-1.5-7b-hf", description="Tag-filter language model (endpoint model name or local id).")
    articulation_endpoint: str | None = Field(None, description="OPDMulti HTTP endpoint or command (JSON contract).")
    batch_size: int = Field(8, ge=1, description="Frames per model call on GPU.")
    device: str = Field("auto", description="'auto', 'cpu', 'cuda', 'cuda:N'.")
    oracle: OracleNoiseConfig = Field(default_factory=OracleNoiseConfig, description="Oracle backend: how imperfect its ground truth is made.")
    heuristic: HeuristicConfig = Field(default_factory=HeuristicConfig, description="Heuristic backend: facets, front rules, image path, sliding doors.")

    @field_validator("tag_filter_endpoint", "articulation_endpoint")
    @classmethod
    def _no_credentials(cls, value: str | None, info: ValidationInfo) -> str | None:
        """Endpoints are recorded in scene.json and in Prefect's flow-run parameters, so they must not carry a
        secret: keys come from the environment (REACT3D_LLM_API_KEY / OPENAI_API_KEY,
        REACT3D_OPDMULTI_API_KEY) or a Prefect Secret block, never from the config."""
        if value:
            where = endpoint_credential(value)
            if where:
                field = info.field_name
                # ConfigError, not ValueError: pydantic would wrap a ValueError and echo the input (the key)
                raise ConfigError(f"perception.{field} carries a credential ({where}); it would be stored in scene.json "
                                 "and Prefect's run parameters. Remove it and set the key in the environment "
                                 "(REACT3D_LLM_API_KEY, REACT3D_OPDMULTI_API_KEY; docs/reliability.md) "
                                 "or in a Prefect Secret block")
        return value


_URL = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*://[^\s'\"]+")
_SECRET_NAME = re.compile(r"^(.*[-_])?(api[-_]?key|key|token|access[-_]?token|secret|password|passwd|pwd|auth|"
                          r"authorization|signature|sig|credentials?)$", re.IGNORECASE)
_SECRET_FLAG = re.compile(r"(?:^|\s)--?(api[-_]?key|token|access[-_]?token|secret|password|auth)(?:[=\s]|$)", re.IGNORECASE)


def endpoint_credential(value: str) -> str | None:
    """Where ``value`` (a URL, or a command that may contain URLs) carries a credential, else None:
    user info in a URL, a query parameter named like a key/token, or a ``--api-key``-style flag."""
    for url in _URL.findall(value):
        parts = urlsplit(url)
        if "@" in parts.netloc:
            return "user name/password in the URL"
        for name, _ in parse_qsl(parts.query, keep_blank_values=True):
            if _SECRET_NAME.match(name):
                return f"query parameter {name!r}"
    m = _SECRET_FLAG.search(value)
    return f"command-line flag {m.group(0).strip().split('=')[0]!r}" if m else None

