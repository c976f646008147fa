"""The weight-free heuristic perception backend: front rules on the scan mesh, the image path, sliding doors.

One section per part of the heuristic, named after what reads it (``perception.heuristic.ortho`` is read by
perception/heuristic/orthophoto.py); the code takes the section itself, so each threshold is declared here
once, with its description. Renamed keys of the earlier flat layout are rejected with their new name
(``RENAMED``).
"""

from typing import Any, Literal

from pydantic import Field, model_validator

from ._base import StageConfig


class FacetConfig(StageConfig):
    """Planar facets of the scan mesh (perception/heuristic/facets.py)."""

    weld_m: float = Field(0.001, gt=0, description="Vertices closer than this (m) are merged before faces are joined.")
    max_angle_deg: float = Field(12.0, ge=0, le=180, description="Faces sharing an edge join when their normals differ by at most this (deg).")


class ProbeConfig(StageConfig):
    """Which facets the cameras see (perception/heuristic/backend.py): a few frames rendered small."""

    frames: int = Field(24, ge=1, description="Frames (evenly spread) rendered to find which facets the cameras see.")
    downscale: int = Field(4, ge=1, description="... each at the colour size divided by this (4: quarter size).")
    view_px: int = Field(4, ge=1, description="A facet counts as seen in a probe view with at least this many pixels ...")
    min_views: int = Field(2, ge=1, description="... and is visible when seen in this many probe views ...")
    min_px: int = Field(40, ge=0, description="... with at least this many pixels over all probe views.")


class RenderConfig(StageConfig):
    """Per-frame front renders that the five perception calls read (perception/heuristic/backend.py)."""

    scale: float = Field(0.5, gt=0, le=1, description="Fronts are rendered at this fraction of the colour size (upsampled).")
    min_mask_px: int = Field(150, ge=0, description="A front yields a mask in a frame when it covers at least this many pixels there.")


class FrontRulesConfig(StageConfig):
    """The heuristic's front rules on the scan mesh (perception/heuristic/fronts.py): which planar
    facets are openable fronts, their handles and frames, and the joint guessed from shape and handle."""

    min_w: float = Field(0.12, gt=0, description="Narrowest front (m).")
    max_w: float = Field(1.3, gt=0, description="Widest front (m).")
    min_h: float = Field(0.1, gt=0, description="Lowest front (m).")
    max_h: float = Field(2.3, gt=0, description="Tallest front (m).")
    max_tilt: float = Field(0.25, ge=0, le=1, description="A front is vertical: |n_z| of its normal at most this (also bounds the image path's planes).")
    min_fill: float = Field(0.8, ge=0, le=1, description="A front's facet fills at least this share of its bounding rectangle.")
    ring_min_fill: float = Field(0.15, ge=0, le=1, description="A door-sized facet filling less than min_fill but at least this share of its rectangle is a ring: the frame of a frame-and-panel front whose panel is too small to be a front itself.")
    handle_max_area: float = Field(0.03, gt=0, description="Largest handle facet (m^2); also the largest rim/bevel facet added to a front.")
    handle_depth: tuple[float, float] = Field((0.002, 0.09), description="Handle facets stand this far in front of the front's plane (min, max; m).")
    handle_min_cos: float = Field(-0.3, ge=-1, le=1, description="A handle facet's normal has at least this cosine with the front's normal (a facet facing back at the front is another object's).")
    rect_slack: float = Field(0.005, ge=0, description="Rectangle tests allow this much (m): a handle's centre lies this far inside its front, a frame piece (or a ring's panel) within the rectangle grown by it, and a frame piece borders a side when it reaches this far past the edge.")
    parallel_cos: float = Field(0.97, ge=0, le=1, description="Two facets or fronts face the same way when the cosine between their normals is at least this (frame pieces, covering and neighbouring fronts, a mesh front and the plane it is judged on).")
    coplanar_offset: float = Field(0.03, ge=0, description="Parallel fronts whose planes are at most this far apart (m) are coplanar (neighbours, fronts of one row).")
    neighbour_align: float = Field(0.05, ge=0, description="Neighbours side by side share top and bottom edges, stacked ones left and right edges, within this (m).")
    cover_depth: tuple[float, float] = Field((0.001, 0.08), description="A candidate covers another's facet when it stands this far in front of it (min, max; m): the other is a carcass face seen through the gaps once more than half of it is covered.")
    drawer_max_h: float = Field(0.45, gt=0, description="Drawers are at most this tall (m): deep drawers reach ~0.45 m, oven/dishwasher doors are >= 0.5 m.")
    drawer_travel: float = Field(0.3, gt=0, description="A drawer's guessed travel (m): the upper limit of its prismatic joint.")
    flap_min_top: float = Field(1.2, ge=0, description="A top-hinged flap lifts upwards: its top is above this height (m, z up from the floor), above a worktop.")
    flap_max_h: float = Field(1.2, gt=0, description="A top-hinged flap or a bottom-hinged drop door is at most this tall (m): a taller front with a horizontal bar (a fridge door, a tall cabinet door) is hinged at a side.")
    flap_max_deg: float = Field(90.0, gt=0, description="A flap's or drop door's guessed opening (deg).")
    door_max_deg: float = Field(100.0, gt=0, description="A side-hinged door's guessed opening (deg).")
    neighbour_gap: float = Field(0.03, ge=0, description="Coplanar fronts closer than this (m) are neighbours (door pairs, drawer stacks).")
    knob_max_aspect: float = Field(2.0, ge=1, description="A handle whose extent one way is less than this times the other is a knob, which has no direction: ...")
    knob_max_size: float = Field(0.07, gt=0, description="... and is at most this across both ways (m; knobs are 2.5-6.5 cm, handles.knob_size): a larger compact blob in a front's middle (a raised panel's boss, a badge) has no knob's place to read, and keeps the bar reading.")
    knob_centre: float = Field(0.25, ge=0, le=0.5, description="... within this share of the front's width from its vertical centre line it is read as a horizontal bar (a drawer's or a flap's knob), farther out as a vertical one (a door's, at its opening edge).")
    row_overlap: float = Field(0.01, ge=0, description="Fronts in a row (doors_in_rows) may overlap side by side by this much (m) ...")
    row_min_height_share: float = Field(0.7, ge=0, le=1, description="... and share at least this part of the smaller one's height.")
    row_door_min_h: float = Field(0.5, ge=0, description="A front with a horizontal bar at least this tall (m) beside a drop-door guess makes a row of cabinet doors, not an oven.")
    frame_max_width: float = Field(0.2, ge=0, description="Widest stile/rail of a frame-and-panel front (m).")
    frame_max_gap: float = Field(0.015, ge=0, description="A frame piece lies at most this far (m) from the panel it frames.")
    frame_claim_margin: float = Field(0.003, ge=0, description="A frame piece two panels claim goes to the one it lies closer to by more than this (m); to neither on a tie (a face-frame rail between two doors).")
    frame_min_sides: int = Field(3, ge=1, le=4, description="A frame borders at least this many sides of its panel (a single rail beside a front is the carcass).")
    frame_panel_max_fill: float = Field(0.85, ge=0, le=1, description="A panel filling more than this share of the frame-and-panel rectangle is a plain front with slivers around it: nothing is absorbed.")
    frame_depth: tuple[float, float] = Field((0.001, 0.03), description="Frame pieces stand this far proud of a recessed panel (min, max; m) ...")
    raised_depth: tuple[float, float] = Field((-0.016, -0.003), description="... or a raised panel stands this far proud of them (min, max; m, negative: frame behind the panel).")
    rim_depth: float = Field(0.03, ge=0, description="A front's edge/bevel facets reach this far behind its plane (m) ...")
    rim_front: float = Field(0.01, ge=0, description="... at most this far in front of it (m) ...")
    rim_margin: float = Field(0.02, ge=0, description="... and this far outside its rectangle (chamfered edges; m).")


class FloorConfig(StageConfig):
    """The floor's height, for the rules that measure from it (image fronts, room doors, drawers in reach)."""

    min_area: float = Field(0.5, ge=0, description="The floor is the lowest band of upward-facing mesh holding at least this area (m^2), at its area-weighted median height; no such band: no floor rule in the image path, the mesh's lowest point elsewhere.")
    band: float = Field(0.02, gt=0, description="Height of that band (m).")
    min_up: float = Field(0.9, ge=0, le=1, description="Upward-facing: the face normal's z is above this.")


class ReachConfig(StageConfig):
    """Drawers are within reach (perception/heuristic/reach.py)."""

    drawer_max_top: float = Field(1.7, ge=0, description="A drawer's top edge is at most this high above the floor (m): nothing slides out above eye level; a drawer-typed strip higher up is dropped; 0: no limit.")


class LidConfig(StageConfig):
    """A chest's front with a bar at its top is the lid's lip: the lid is the chest's top (perception/heuristic/lids.py)."""

    enabled: bool = Field(True, description="Turn a wide drop-typed front level with a flat top of its own width into that top's lid, hinged at its back edge.")
    min_w: float = Field(0.7, ge=0, description="Only fronts at least this wide (m): dishwasher and oven drop doors are 0.45-0.6 m.")
    min_up: float = Field(0.9, ge=0, le=1, description="The top's faces: the normal's z is above this.")
    band: float = Field(0.04, gt=0, description="The top lies level with the front's top edge within this (m); also the slack of the lid's box.")
    min_depth: float = Field(0.4, gt=0, description="The top covers the rectangle this deep behind the front (m) ...")
    cover: float = Field(0.6, ge=0, le=1, description="... by at least this share.")
    max_depth: float = Field(1.0, gt=0, description="The lid reaches back at most this far (m).")
    side: float = Field(0.2, gt=0, description="Strips this wide (m) beside the front, level with its top ...")
    side_cover: float = Field(0.3, ge=0, le=1, description="... covered by at least this share mean a worktop runs on past it: a drop door under a worktop, not a lid.")
    lip: float = Field(0.08, ge=0, description="The lid reaches this far below its top (m): its lip with the bar.")


class SplashbackConfig(StageConfig):
    """Fronts standing on a worktop flush with the wall behind it are splash-back (perception/heuristic/splashback.py)."""

    enabled: bool = Field(True, description="Drop fronts standing on a worktop flush with the wall behind it (splash-back: tiles, sockets).")
    min_z: float = Field(0.5, ge=0, description="The worktop under the front's bottom edge is above this height (m).")
    band: float = Field(0.08, ge=0, description="The worktop is this close to the front's bottom edge in height (m).")
    reach: tuple[float, float] = Field((0.03, 0.33), description="The strip in front of the front examined for a worktop (m in front, from/to).")
    cover: float = Field(0.2, ge=0, le=1, description="Share of that strip the worktop must cover.")
    min_up: float = Field(0.7, ge=0, le=1, description="Worktop faces: the normal's z is above this (a scanned worktop is noisy and cluttered: its faces tilt).")
    run_depth: tuple[float, float] = Field((0.45, 0.8), description="A front also stands on a worktop when another front, this far in front of it (m, from/to: a worktop's depth; a microwave's door is nearer the run's front line), overlaps it across with its top edge within band of the front's bottom: the run under a worktop the mesh lacks (black granite returns no depth). (0, 0): off.")
    wall_ring: float = Field(0.3, ge=0, description="A front is kept when the wall stands behind it (an appliance on the worktop, pushed back): surface in a ring this wide (m) around its sides and top ... (0: no such test)")
    wall_behind: tuple[float, float] = Field((0.2, 1.0), description="... lying this far behind its plane (m, from/to), facing the same way ...")
    wall_share: float = Field(0.1, ge=0, le=1, description="... covers at least this share of the ring.")
    worktop_rise: float = Field(0.07, ge=0, description="For that run: the front's bottom edge may also lie up to band + this (m) above the run's top edge (the worktop's thickness and the gap between it and the run's fronts).")


class RoomWallConfig(StageConfig):
    """On the room's outer walls only room doors open (perception/heuristic/room_walls.py)."""

    enabled: bool = Field(True, description="On the room's outer walls (planes with no scan surface behind them) keep only fronts shaped like room doors, typed as side-hinged doors.")
    behind_share: float = Field(0.005, ge=0, le=1, description="Outer wall: less than this share of the scan's surface area lies behind the front's plane ...")
    depth: float = Field(0.1, ge=0, description="... more than this far (m) ...")
    min_area: float = Field(1.0, ge=0, description="... and the plane holds at least this much other surface (m^2) outside every front (a lone cabinet scanned from the front has no wall).")
    plane_tol: float = Field(0.03, ge=0, description="Surface in the front's plane: faces within this of it (m) ...")
    plane_min_cos: float = Field(0.9, ge=0, le=1, description="... facing the same way (cosine between the normals above this).")
    wall_back: float = Field(0.3, ge=0, description="Surface behind the plane facing away from the room (cosine below -plane_min_cos), less than this (m) behind it, is the wall's own outer side (a modelled wall's thickness; no camera inside the room sees it), not scanned surface behind the wall (0: it counts).")
    wall_band: float = Field(0.1, ge=0, description="Surface up to this far (m) behind the front's plane counts as in it too: a radiator or a picture stands a few cm proud of the wall, with the wall around it and nothing behind (0: only plane_tol).")
    door_min_h: float = Field(1.8, gt=0, description="Room door on an outer wall: at least this tall (m) ...")
    door_w: tuple[float, float] = Field((0.6, 1.3), description="... this wide (min, max; m) ...")
    door_floor_gap: float = Field(0.05, ge=0, description="... and its bottom edge this close to the floor (m).")


class SlidingConfig(StageConfig):
    """Sliding doors: two fronts on two tracks (perception/heuristic/sliding.py)."""

    track_offset: tuple[float, float] = Field((0.008, 0.06), description="Plane offset between two side-by-side fronts on two tracks (m).")
    max_overlap: float = Field(0.12, ge=0, description="The two fronts' outlines overlap by at most this (m) ...")
    max_gap: float = Field(0.02, ge=0, description="... or leave at most this gap between them (m).")
    min_height_overlap: float = Field(0.9, ge=0, le=1, description="Share of the smaller height the two fronts share.")
    min_parallel: float = Field(0.97, ge=0, le=1, description="|cos| between the two fronts' normals at least this.")
    min_travel: float = Field(0.05, gt=0, description="A sliding door's travel (its width less the overlap) is at least this (m).")


class ImageConfig(StageConfig):
    """Fronts found in the colour frames (perception/heuristic/image_fronts.py): cells of the plane
    orthophotos become fronts."""

    enabled: bool = Field(True, description="Also find fronts in the colour frames (real scans have no seams in the mesh).")
    texture_factor: float = Field(3.0, ge=0, description="Handle/seam thresholds rise to this many times the plane's median response (textured planes).")
    face_depth: tuple[float, float] = Field((-0.02, 0.07), description="Faces this far behind/in front of the plane are taken into a front (m).")
    surface_rays: bool = Field(False, description="A plane's coverage and the handles standing out of it are read from rays cast along its normal through every orthophoto pixel (the same on any tessellation of the scan); off: from its faces' centroids splatted on the grid (a decimated scan's planes come out mostly uncovered).")
    rays_face_edge: float = Field(0.015, ge=0, description="A plane whose faces are coarser than this (area-weighted median of sqrt(2 x face area), m) reads its coverage and handles from rays as with surface_rays: a decimated scan's centroids lie too far apart for coverage_close to join (0: only with surface_rays).")
    modelled_share: float = Field(0.5, ge=0, le=1, description="... unless this share of its area lies in groups of faces with one exact normal (a modelled scene's plane: CAD or a clean synthetic mesh, whose fronts the mesh rules cut by exact seams; rays there cut panels and bevels into false cells; 0: never).")
    seen_reach: float = Field(0.05, ge=0, description="With surface_rays, the plane's coverage is only the scan surface within this (m) of a pixel some view sees (handle shadows and the outlines taken off every view at depth edges stay in): a complete mesh holds surface no camera saw (the wall behind cabinets), whose cells became fronts (0: every surface in the slab).")
    coverage_tilt_deg: float = Field(0.0, ge=0, le=90, description="Without rays, whether a cell is covered (cells.min_seen) is read from the plane's faces and those in its slab (coverage_tilt_depth, inside its extent) whose normals are tilted from the plane's by at most this (deg; 0: only the plane's own faces); the cells are still cut on the plane's own faces: a TSDF raised-panel or shaker front's bevels and rounded frame tilt its faces beyond planes.angle_tol_deg, so only 25-40 % of such a front was its plane's and its cell fell under cells.min_seen.")
    coverage_tilt_depth: float = Field(0.025, ge=0, description="... those faces lying at most this far (m) in front of or behind the plane.")
    coverage_close: float = Field(0.02, ge=0, description="The plane's coverage (its faces' centroids, or with surface_rays the scan surface lying flat in its slab, on the orthophoto grid) is closed over this (m).")
    outline_fill_px: int = Field(20, ge=0, description="Holes and notches up to this many orthophoto px wide are inside a plane's outline (handle shadows).")
    min_faces: int = Field(4, ge=1, description="An image front holds at least this many mesh faces.")
    pane_frame: float = Field(0.035, ge=0, description="A hole in a plane's coverage framed all round by at least this much (m) of the plane's surface is a glass pane of a front (the scan lacks it, the views see through it): it counts as covered for cells and their outlines (0: holes stay holes).")
    pane_frame_cover: float = Field(0.85, ge=0, le=1, description="... framed: this share of the band of width pane_frame around the hole is covered (glass tuning: every hole passing the size and fill tests had 0.855-1.0, all inside glass doors or windows; a laser wall cabinet's ragged inner frame edges gave 0.898, under the former 0.9) ...")
    pane_min_area: float = Field(0.01, ge=0, description="... the hole is at least this large (m²) ...")
    pane_min_side: float = Field(0.1, ge=0, description="... and its bounding box at least this wide and tall (m): a handle's scanning shadow on a TSDF front is a hole framed all round by the front, 2-6 cm wide (filled, held-apart TSDF kitchen 200 lost fronts: F1@0.5 0.84 -> 0.47).")
    pane_min_fill: float = Field(0.8, ge=0, le=1, description="... and it fills at least this share of its bounding box (a pane is a rectangle cut to its frame: 0.90-1.00 on the glass tuning scenes; the scanning shadows of bar handles on TSDF drawers are ragged blobs, 0.27-0.65).")
    pane_solid_share: float = Field(0.5, ge=0, le=1, description="A framed hole whose area the scan covers by at least this share with faces facing out within pane_solid_depth of the plane (their areas projected onto it) is a solid panel, not a glass pane: a raised panel's tilted middle is no part of its plane and is framed all round by its bevels, and taken for glass it blocked every cut through its columns (1: never).")
    pane_solid_depth: float = Field(0.015, ge=0, description="... faces within this (m) in front of or behind the plane: a panel's surface lies within a centimetre of the frame's plane; what stands behind glass lies beyond the frame's depth.")
    pane_seen: bool = Field(True, description="Panes are sought in the coverage joined with what the views see at the plane's depth: on a TSDF glass door the frame is thin and its fused surface ragged or rounded off the plane, so the coverage holds a few bits of it and the pane runs into the open; the views see the whole frame (glass tuning TSDF scene 320: 0 of 7 glass doors framed in the coverage). Off: the coverage alone, as before.")
    pane_seen_reach: float = Field(0.035, ge=0, description="... what the views see within this (m) of the coverage: farther in, what stands behind the glass close to it (books on a shelf, seen at the plane's depth on laser scans) closed the panes (glass tuning laser scene 325: 13 -> 8 parts found with it unbounded).")
    pane_seen_max_cover: float = Field(0.9, ge=0, le=1, description="... on a plane whose coverage holds less than this share of what the views see near it (a fused surface in rags); on others panes are sought on the coverage alone, no specks taken off nor gaps closed: glass tuning laser 321's planes with glass doors hold 94-97 % of it, and there the extra panes cut cells wrong (321: 12 -> 8 parts found without this bound); the TSDF glass cupboard and sideboard of 326 77 %.")
    pane_seen_rim: float = Field(0.035, ge=0, description="... and what the views see within this (m) of the plane's top and bottom edges as they see them (the first seen pixel of each column from above and below), however far from the coverage: a TSDF cupboard's top rail lies on the fused box's rounded edge, outside the coverage and beyond pane_seen_reach, and its pane ran out over the top (0: off). A carcass board's edge is thinner than pane_speck and is taken off again. Glass tuning, front level: F1 0.793 -> 0.809 (320 two wall-cabinet doors, 324 one).")
    pane_seen_rim_sides: bool = Field(False, description="... and within pane_seen_rim of the plane's left and right edges as the views see them (the first seen pixel of each row from either side): the outer stiles of a TSDF cupboard's end doors lie on the fused box's rounded side edges as its top rail lies on the top one. Off by default: on glass tuning 2 it found 2 more doors, but it cost a drawer under a microwave (whose sides it took for a frame) and 4 fronts on a clean scene-synthesizer kitchen (held-apart 109: 28 -> 24).")
    pane_speck: float = Field(0.02, ge=0, description="... with covered strokes and specks thinner than this (m) taken off first: a shelf's front edge or a jar behind the glass, seen at the plane's depth, split a pane or took its fill; a frame is wider (0: nothing taken off).")
    pane_gap: float = Field(0.08, ge=0, description="... and gaps up to this (m) closed: a rail the fusion broke in places let the pane run out into the open (glass tuning TSDF scene 320: gaps of 4-8 cm in the wall cabinets' top rails; 0: none closed). Holes this small are closed too, but a pane is at least pane_min_side across.")
    pane_rounds: int = Field(3, ge=1, description="Framed panes are sought this many times, each time with the panes found so far counted as frame (a shelf seen through a pane splits it into two holes).")
    pane_bar: float = Field(0.02, ge=0, description="Panes are closed over this (m): a shelf edge seen through a pane, or a glazing bar, between two panes is part of the door, not a seam.")
    pane_cell_cover: bool = Field(True, description="Panes count as covered when a cell's coverage is tested (cells.min_seen), as they do when cells are cut: a TSDF glass door's own surface is its frame, 20-50 % of its cell, so without them the door's cell fell under min_seen (glass tuning set, front level: 67 -> 88 of 124 parts found). Off: the cell's test reads the plane's surface alone.")
    glass_behind: float = Field(0.8, ge=0, description="A front most of whose rectangle lies up to this far (m) behind a pane that another plane's fronts frame, its foot along that plane's normal inside the pane grown by glass_behind_grow, is the inside of a glass cabinet seen through the door (a side wall, a partition, a shelf's lip as its handle), not a front (glass tuning laser scans: a vitrine's sides and a cupboard's partitions, 4 false doors on 321). 0: off.")
    glass_behind_min: float = Field(0.03, ge=0, description="... and at least this far (m) behind it (a front on the pane's own plane is the glass door itself).")
    glass_behind_share: float = Field(0.5, ge=0, le=1, description="... share of the front's rectangle (25 sample points) that must lie so.")
    glass_behind_grow: float = Field(0.09, ge=0, description="... the panes grown by this much (m): the door's frame (5-8 cm on glass doors), behind which the cabinet's side walls and partitions stand.")
    pane_fill: bool = Field(True, description="A pane takes the median colour of the frame around it and counts as seen (off: it stays without colour, and seams through glass doors are judged on their rails alone).")
    pane_edge: float = Field(0.02, ge=0, description="... the frame's colour is read from this far (m) out from the pane to pane_frame beyond (its shaded inner edge left out).")
    mesh_share: float = Field(0.3, ge=0, le=1, description="An image front lying on a mesh front's faces by more than this share of its faces is left to the mesh front (which stands unless it holds two image fronts with handles).")
    plain_floor_gap: float = Field(0.03, ge=0, description="A handle-less front whose bottom edge is this close to the floor (m) is a piece of wall (base units stand on a plinth; room doors have handles); 0: no floor rule.")
    veto_plane_offset: float = Field(0.08, ge=0, description="A mesh front is judged on the orthophoto of a parallel plane at most this far from it (m) ...")
    veto_min_px: int = Field(5, ge=1, description="... when its rectangle there is at least this many px both ways ...")
    veto_min_seen: float = Field(0.3, ge=0, le=1, description="... and this share of it is seen; it is clutter (a tiled wall with a socket 'handle') when more than clutter.max_share of its pixels are off their background by handles.contrast.")


class PlanesConfig(StageConfig):
    """Large vertical planes of the mesh for the image path (perception/heuristic/planes.py)."""

    offset_tol: float = Field(0.025, ge=0, description="Faces this close to a vertical plane belong to it (m).")
    angle_tol_deg: float = Field(12.0, ge=0, description="Faces whose normal is within this of a plane's belong to it (deg).")
    direction_smooth_bins: int = Field(5, ge=1, description="The normals' direction histogram (1-degree bins) is smoothed over this many bins.")
    direction_min_sep_bins: int = Field(6, ge=1, description="Direction peaks are at least this many 1-degree bins apart.")
    direction_peak_div: float = Field(5.0, gt=0, description="A direction peak holds at least min_area divided by this (m^2 per bin, smoothed).")
    offset_bin: float = Field(0.005, gt=0, description="Bin of the plane-offset histogram along a direction (m).")
    offset_peak_div: float = Field(10.0, gt=0, description="An offset peak holds at least min_area divided by this (m^2 per bin, smoothed over offset_tol).")
    refit_deg: float = Field(3.0, ge=0, description="A plane at least refit_min_extent wide takes, within this of its normals' mean direction, the direction along which its faces' positions are sharpest (a curved appliance door skews the normals; deg, 0: off).")
    refit_min_gain: float = Field(1.4, ge=1, description="... only when the offsets are at least this many times sharper (integral of the squared density) than along the normals' direction ...")
    refit_keep_share: float = Field(0.9, ge=0, le=1, description="... and the refitted plane keeps at least this share of the area it had (turned onto another surface, it does not).")
    refit_min_extent: float = Field(1.0, ge=0, description="Refit only planes with an unbroken stretch at least this long (m) ...")
    refit_run_step: float = Field(0.04, gt=0, description="... unbroken on a grid of this step (m).")
    refit_step_deg: float = Field(0.1, gt=0, description="Directions tried by the refit are this far apart (deg).")
    refit_bin: float = Field(0.002, gt=0, description="The refit's offset density: bins of this size (m) ...")
    refit_sigma: float = Field(0.003, gt=0, description="... smoothed by a Gaussian of this sigma (m).")
    max_skew_deg: float = Field(5.0, ge=0, description="A plane piece whose faces' normals are turned from its own normal by more than this on average (area-weighted, deg) is a slice through a surface at another angle (a turned cabinet's front cut along a wall's direction), not a plane; its faces vote again (0: no such test).")
    normal_agree: float = Field(0.5, ge=0, le=1, description="A plane faces the way its faces' normals point when their area-weighted mean along its normal is at least this either way (a scan's faces face the free space the sensor looked through), else towards the cameras' mean position, which for a piece standing free in the room facing a wall lies behind it (0: always the cameras' mean position).")
    revote_rounds: int = Field(1, ge=0, description="Rounds in which the vertical faces no plane holds vote again for directions at least direction_min_sep_bins from those found (a piece of furniture turned by ~10 degrees is hidden in the first vote by the walls' peak; 0: one vote).")
    smooth_rings: int = Field(0, ge=0, description="Opt-in (0: off; measured at 3). A last vote of the vertical faces no plane holds, by their normals averaged over this many rings of neighbouring faces: a piece a few metres from the sensor on a 1 cm TSDF scan has face normals spread by +-15 degrees and no direction peaks (turned free-standing pieces, TSDF free-standing tuning 11 drawers). Off by default: on RedKitchen it added a plane over a wall cabinet cut into a false part in every view set (every 5th frame 7 / 0 -> 7 / 1).")
    smooth_peak_div: float = Field(10.0, gt=0, description="... in which a direction peak holds at least min_area divided by this (m^2 per bin, smoothed; averaged normals still spread by +-5 degrees).")
    residual_dip: float = Field(0.0, ge=0, le=1, description="Opt-in (0: off; measured at 0.75). The faces of a direction that no offset peak took vote again; a peak of theirs is a plane too when all the direction's faces' offsets dip below this share of it on the way to the nearest peak taken: a microwave's front 3-6 cm behind its cabinet's peaks on that front's flank, inside the peaks' separation; a wall's tail or a bent wall's plateau has no dip. Off by default: on RedKitchen the planes it adds (and the turned wall unit the next vote then finds) are cut into fronts at box IoU 0.3-0.55, default keyframes 5 / 1 -> 6 / 3, and on 22 tuning scenes it found 1 front more for 2 more predictions (a porthole door on its own plane lost).")
    residual_stack_depth: float = Field(0.08, ge=0, description="... unless it lies on the footprint of a first-vote plane within this offset of it (m) ...")
    residual_max_stack: float = Field(0.5, ge=0, le=1, description="... on more than this share of its 4 cm grid cells (a front's frame or panel, the plinth behind its fronts, a TSDF scan's doubled surface: relief on one front, not a front beside it).")
    min_area: float = Field(0.05, ge=0, description="Smallest vertical plane photographed (m^2; at least fronts.min_w x fronts.min_h). A microwave's door around its glass window holds 0.06-0.08 m² of scan surface on its plane.")
    cell: float = Field(0.04, gt=0, description="Pieces of one plane farther apart than this are separate planes (m).")
    min_fragment_area: float = Field(0.03, ge=0, description="Fragments of a plane's coverage smaller than this are not part of it (m^2).")
    slope_win: float = Field(0.012, gt=0, description="A plane's coverage is the scan surface in its slab (offset_tol) tilted by at most angle_tol_deg, the tilt measured on the surface's offsets averaged over this window (m; at least 3 orthophoto px).")


class OrthoConfig(StageConfig):
    """Fused orthophotos of the planes (perception/heuristic/orthophoto.py)."""

    resolution: float = Field(0.004, gt=0, description="Metres per pixel of the fused plane orthophotos.")
    max_side_px: int = Field(1200, ge=1, description="Orthophotos of very large planes get a coarser grid, at most this many px a side.")
    max_views: int = Field(30, ge=1, description="Views fused per plane at most.")
    pick_spread: bool = Field(False, description="Views are picked for coverage, sharpness and diversity (pick_*); off: the max_views frames seeing most of the plane most frontally (a dense walk's neighbouring frames, all alike).")
    pick_samples: int = Field(9, ge=1, description="Views are picked on this many x this many sample points of a plane ...")
    pick_need: int = Field(8, ge=1, description="... each wanting this many views; a view is worth the sum of its sharpness (cosine to the normal over distance) at the samples that still want views ...")
    pick_sep: float = Field(0.15, ge=0, description="... and once one is taken, views whose camera is within this (m) ...")
    pick_sep_deg: float = Field(10.0, ge=0, description="... and whose optical axis is within this (deg) of it are passed over (a dense walk's next frames add nothing new).")
    min_cos: float = Field(0.3, ge=0, le=1, description="Views more grazing than this cos to the plane are not used.")
    render_scale: float = Field(0.5, gt=0, le=1, description="Face-id buffer size relative to the colour image.")
    erode_px: int = Field(3, ge=0, description="Depth-buffer pixels kept this far from depth jumps (occluder outlines).")
    edge_jump: float = Field(0.05, gt=0, description="A depth jump between neighbouring pixels marking an outline (m).")
    depth_tol: float = Field(0.03, ge=0, description="A plane point is seen when the scan is within this (m) ...")
    depth_tol_rel: float = Field(0.01, ge=0, description="... plus this share of its distance from the camera.")
    min_view_px: int = Field(50, ge=1, description="A view is fused into a plane's orthophoto when it sees at least this many of its grid pixels.")
    margin: float = Field(0.02, ge=0, description="Grid margin around a plane's extent (m).")


class CalibrationConfig(StageConfig):
    """Self-calibration of the colour intrinsics against the mesh (perception/heuristic/orthophoto.py)."""

    enabled: bool = Field(True, description="Self-calibrate colour focal scale / principal point against the mesh (unregistered RGB-D).")
    scale_range: tuple[float, float] = Field((0.84, 1.12), description="Focal scales searched ...")
    scale_steps: int = Field(15, ge=2, description="... in this many steps (coarse pass).")
    shift_range_px: float = Field(16.0, ge=0, description="Principal-point shifts searched (px at 640 px width) ...")
    shift_steps: int = Field(5, ge=2, description="... in this many steps each way (coarse pass).")
    fine_scales: tuple[float, ...] = Field((-0.02, -0.01, 0.01, 0.02), description="Fine pass: focal-scale changes tried around the best.")
    fine_shift_px: float = Field(3.0, ge=0, description="Fine pass: shifts of this much (px at 640 px width) tried each way around the best.")
    planes: int = Field(2, ge=1, description="Calibrated on this many planes, those seen most ...")
    max_views: int = Field(12, ge=1, description="... each on its views seeing most of it, at most this many ...")
    min_views: int = Field(3, ge=2, description="... at least this many; disagreement on grid pixels seen this many times ...")
    min_px: int = Field(100, ge=1, description="... at least this many of them (else the plane says nothing).")
    min_gain: float = Field(0.2, ge=0, le=1, description="Used only when it cuts the disagreement by this fraction.")


class RegistrationConfig(StageConfig):
    """Per-view colour registration, opt-in (perception/heuristic/view_registration.py)."""

    sigmas_px: tuple[float, ...] = Field((), description="Image blur per coarse-to-fine level (px at 640 px width), e.g. [12, 6, 3, 1.5]; () = off. For RGB-D whose colour is not synchronised with depth (docs/perception.md: what it gains and costs).")
    prior_scale: float = Field(0.08, gt=0, description="Prior std of a view's focal scale and aspect around the scene calibration.")
    prior_shift_px: float = Field(30.0, gt=0, description="Prior std of a view's shift (px at 640 px width).")
    rounds: int = Field(2, ge=1, description="Per level: re-fuse the median this many times, each followed by Gauss-Newton steps per view ...")
    iters: int = Field(3, ge=1, description="... at most this many.")
    min_views: int = Field(3, ge=1, description="A grid pixel takes part when this many views see it.")
    min_points: int = Field(2000, ge=1, description="A view with fewer such pixels keeps the scene calibration (8 mm grid: ~0.13 m^2).")
    band: float = Field(2.0, ge=0, description="Signal: log brightness blurred at sigma less blurred at band x sigma (0: less the plane mean).")
    reach: float = Field(2.0, ge=0, description="Points nearer than reach x (band or 1) x sigma to a depth jump are left out.")
    min_gain: float = Field(0.1, ge=0, le=1, description="A view keeps its correction when it cuts its disagreement by this fraction.")
    max_scale_step: float = Field(0.02, gt=0, description="A Gauss-Newton step changes a view's focal scale by at most this (its shift by at most sigma).")
    converged_shift_px: float = Field(0.05, ge=0, description="Steps stop once the shift moves less than this (px at 640 px width) ...")
    converged_scale: float = Field(1e-4, ge=0, description="... and the focal scale less than this.")


class SeamConfig(StageConfig):
    """Seams that cut a plane's orthophoto into cells (perception/heuristic/front_cells.py)."""

    contrast: float = Field(0.01, ge=0, description="A seam pixel is this much darker than both sides (fraction of the plane's mean).")
    width_px: int = Field(3, ge=1, description="A seam pixel is darker than both neighbours 1 to this many px away; an unseen gap with seen pixels this close on both sides is a seam too.")
    smooth_px: int = Field(9, ge=1, description="Seam maps are smoothed along the seam direction over this many px.")
    span: float = Field(0.35, ge=0, le=1, description="A seam covers this fraction of the cell it splits ...")
    span_chunks: int = Field(3, ge=1, description="... and at least half of it in each of this many equal pieces of its length.")
    prominence: float = Field(0.3, ge=0, le=1, description="... and this much more than the lines around it (vertical seams).")
    prominence_h: float = Field(0.5, ge=0, le=1, description="The same for horizontal seams (reflections of table/shelf edges are horizontal).")
    dip_z: float = Field(15.0, ge=0, description="A straight seam: the line's median brightness dips this many noise units below the lines beside it (found through wood grain).")
    piece_sides: int = Field(3, ge=0, description="... and its median dips by piece_contrast in every piece of its length this many cells.min_side long (0.3 m at 0.1 m): a seam of stacked drawers that spans most of a run does not cut the door beside them. 0: off.")
    piece_contrast: float = Field(0.0005, ge=0, description="How far (fraction of the plane's mean) a straight seam's median dips at least in each piece: a plain door face beside a drawer seam does not dip at all there (clean kitchen 100: -0.1 to 0.0 %); at 0.25 % RedKitchen's 2 cm clustered copy lost two faint seams (4 / 1 -> 2 / 1).")
    min_line_cover: float = Field(0.3, ge=0, le=1, description="Straight seams and colour steps: lines less covered than this share of the best-covered line score 0.")
    noise_floor: float = Field(0.001, gt=0, description="Noise units of straight seams and colour steps are at least this (brightness / colour distance).")
    step_contrast: float = Field(0.25, ge=0, description="A colour step along a whole line (a door leaf in a pale wall) cuts when its colour distance is at least this ...")
    ridges: bool = Field(True, description="In a cell holding no handle, a straight row brighter than the rows beside it (by dip_z noise units, in every piece: the same tests as a dark seam) is a seam too: the top edge of the drawer below, lit from above, which a handle-less chest shows between its drawers (vertical gaps catch no such light; a vertical bright line at a pedestal's lit side edge cut a 10 cm sliver off a drawer).")
    step_z: float = Field(15.0, ge=0, description="... and this many noise units of the cell's steps.")
    step_over_dip: bool = Field(True, description="A colour step along the whole cell that is stronger than the best dark line is the cut (a shaker frame casts a dark line inside its own edge).")
    between_z: float = Field(3.0, ge=0, description="Between two handles the cut is a straight seam of at least this many noise units ...")
    between_span: float = Field(0.2, ge=0, le=1, description="... else the line with most seam evidence, when it covers more than this share; else the middle.")
    knob_pair_gap: float = Field(0.3, ge=0, le=1, description="... except a door pair's: two knobs at one height (their rows overlap), the gap between them at most this share of the cell's width and at least one knob wide, their midpoint within knob_pair_centre of the cell's middle, with no seam between them: cut at that midpoint. The knobs of a pair of doors sit by the stiles where the doors meet, and on black or noisy TSDF fronts that seam shows no line; a wide drawer's two knobs sit at a quarter and three quarters of it (a gap of half its width). 0: off.")
    knob_pair_centre: float = Field(0.1, ge=0, le=0.5, description="... within this share of the cell's width of its middle.")
    clear_of_handles: bool = Field(True, description="Handles are cut apart along the axis they spread more on, unless that cut runs through another handle of the cell and a cut along the other axis does not: a drawer's bar spans the seams between the doors of the row under it, and the cut between two of those doors' handles ran on up through the drawer and its bar (scene-synthesizer kitchens: a drawer over a row of small doors came out as two fronts, each half a drawer and half a door). Off: always the wider spread.")
    knob_seam: bool = Field(True, description="Two knobs side by side in a cell are cut apart only at a seam (between_z or between_span), never at the middle: a wide drawer carries two knobs and an appliance's control panel a row of them, and the middle cut halved such fronts; the two doors of a pair or two drawers in a row meet at a seam.")


class LineConfig(StageConfig):
    """Seams supported by straight line segments found in the colour frames (perception/heuristic/line_evidence.py):
    by OpenCV's LSD (classic_lines.py, no weights; on by default) or by the learned M-LSD (opt-in, weights;
    react3d_models/line_segments.py).
    Visibility along a segment is judged like the orthophotos' (``ortho.render_scale``, ``ortho.erode_px``,
    ``ortho.edge_jump``, ``ortho.depth_tol``, ``ortho.depth_tol_rel``)."""

    enabled: bool = Field(True, description="Run the line-segment detector on a few views of each plane and let seams that its segments support in several views cut cells (docs/perception.md).")
    detector: Literal["lsd", "mlsd"] = Field("lsd", description="lsd: OpenCV's LSD, a classical detector (no weights); mlsd: the learned M-LSD (needs the ai-edge-litert package and its weights, below).")
    gamma: float = Field(0.5, gt=0, le=1, description="lsd reads the grey image lifted to this power: below 1 it spreads the dark levels, where the seam between two black fronts is a few grey levels deep.")
    weights: str | None = Field(None, description="Path to the M-LSD tflite file (M-LSD_512_tiny_fp16.tflite or M-LSD_512_large_fp16.tflite from github.com/navervision/mlsd, tflite_models/); null: the environment variable REACT3D_MLSD_WEIGHTS.")
    threads: int = Field(2, ge=1, description="CPU threads of the detector.")
    min_score: float = Field(0.1, ge=0, le=1, description="Segment centres scoring below this are dropped (the detector's own threshold).")
    min_length_px: float = Field(40.0, ge=0, description="Segments shorter than this (px of the detector's 512 px input) are dropped.")
    max_frames: int = Field(24, ge=1, description="At most this many frames per scene go through the detector (its cost is per frame) ...")
    views_per_plane: int = Field(6, ge=1, description="... each plane read in at most this many of them: those seeing most of it, spread apart (parallax moves what is not on the plane).")
    max_angle_deg: float = Field(4.0, ge=0, le=45, description="A segment on the plane within this of vertical (of horizontal) is vertical (horizontal) line evidence (deg).")
    tol: float = Field(0.015, ge=0, description="Segments of different views this close across (m) support the same line (pose and colour calibration errors move a line by a few cm between views).")
    min_views: int = Field(2, ge=1, description="A grid pixel is on a learned line when segments of at least this many views pass through it.")
    span: float = Field(0.6, ge=0, le=1, description="A learned line cuts a cell that dark lines and colour steps do not when it covers this share of the cell's length (and half of that in each of seams.span_chunks pieces).")


class HandleConfig(StageConfig):
    """Handles in the orthophotos and in the mesh (perception/heuristic/front_cells.py, image_fronts.py)."""

    contrast: float = Field(0.12, ge=0, description="Colour distance of handle pixels from the local background.")
    length: tuple[float, float] = Field((0.1, 0.6), description="Long side of a handle (m): a wide door's bar is up to ~0.5 m and its blob, blurred by the views' misregistration and joined to the shadow beside it, longer (RedKitchen's corner door: its 0.49 m bar, joined to the worktop's shadow band, made a 0.5-0.6 m blob and the door had no handle).")
    strip_length: float = Field(0.5, gt=0, description="Colour runs at least this long along a row or a column are strips (shadow lines along an edge, seams, a plinth's line) and are removed with the pixels beside them before handles are sought; shorter than the longest handle (length): a plinth's 0.5-0.6 m shadow line kept as a handle stopped a dark drawer column's cuts (dark tuning 350).")
    thickness: tuple[float, float] = Field((0.014, 0.07), description="Short side of a handle (m).")
    aspect: float = Field(2.2, ge=1, description="Long side at least this times the short side.")
    min_fill: float = Field(0.4, ge=0, le=1, description="A handle blob fills at least this share of its box.")
    join_gap: float = Field(0.03, ge=0, description="Blob pieces this close along a row (m) are one handle (a bar broken by a highlight).")
    mesh_bar_parts: bool = Field(True, description="A blob (colour and mesh protrusion joined) that is neither a bar nor a knob still yields each piece of it that the mesh's protrusion alone holds and that is a bar: a lip proud along a drawer's top edge joined the dark colour of its top face and the protrusion read along the proud drawer's side into a blob too thick for a handle (off: the blob is dropped whole).")
    min_seen_px: int = Field(100, ge=0, description="A plane with fewer seen orthophoto px has no handles.")
    background_win: float = Field(0.12, gt=0, description="Window of the local background — of the colour, and of the surface a handle in the mesh stands out from (m).")
    outline_margin: float = Field(0.02, ge=0, description="Colour blobs this close to the plane's outline are not handles (m).")
    side_band: float = Field(0.02, gt=0, description="Width of the band around a handle (m) in which the plane's outline is looked for.")
    around_cover: float = Field(0.4, ge=0, le=1, description="The plane's outline covers at least this share of the handle's box grown by side_band (a handle sits on a front).")
    side_cover: float = Field(0.4, ge=0, le=1, description="The plane's outline covers at least this share of the side_band on each long side of a handle (out of the grid counts as uncovered): a handle sits on a front, a ridge at the plane's end (a wall corner, a unit's side) has the plane on one side only (RedKitchen: a door made from a ridge at the tiled wall's end). 0: off.")
    hidden_side: float = Field(0.5, ge=0, le=1, description="A colour-only handle (under bar_share of it standing out of the scan) with at least this share of the side_band along one long side on the plane's surface but seen by no view, and as much of the band hidden_depth out on that side, is the edge of something hiding the plane (a chair, a box, the next piece) or the plane's own lit edge, not a handle: the sides and backs of pieces standing free became doors there (free-standing tuning laser scans, 4 false fronts), and a RedKitchen door was cut in two at the edge of what a chair hides. A handle's scanning shadow is no surface of the scan. 0: off.")
    hidden_depth: float = Field(0.06, ge=0, description="... the hidden surface reaches this far (m) from the handle: a real handle, or a worktop's overhang above a top handle, hides a strip of up to about 5 cm from oblique views (RedKitchen's left run: with the first band alone, 7 of 9 fronts -> 4 at every 5th frame); an occluder hides more. 0: the first band only.")
    few_views: float = Field(0.2, ge=0, le=1, description="A colour-only handle (under bar_share of it standing out of the scan) whose pixels are seen by a median number of views under this share of the median over the plane's seen pixels is no handle: it lies on the shore of what the views see (a base unit's bottom edge seen past an island by one or two grazing views), where colour is one view's, misregistered; the bars a handle is taken from are seen by about as many views as the front around them. 0: off.")
    protrusion_depth: tuple[float, float] = Field((0.012, 0.09), description="Mesh faces this far in front of the plane mark handles (m).")
    protrusion_min_cos: float = Field(0.5, ge=-1, le=1, description="... facing outwards: the cosine between a face's normal and the plane's above this.")
    protrusion_from_surface: bool = Field(True, description="Mesh handles stand protrusion_depth in front of the surface around them (median offset of the faces within background_win) instead of in front of the fitted plane, so a TSDF wall's bumps off its plane are no handles (heuristic version 14, with side_cover). Tuning scenes, front F1: TSDF 0.801 -> 0.812, laser 0.826 -> 0.834 (docs/perception.md).")
    surface_block: float = Field(0.02, gt=0, description="The surface around a mesh handle: the median of per-block medians of the faces' offsets, in blocks of this size (m).")
    bar_close_px: int = Field(5, ge=1, description="A mesh handle's splatted face centroids are closed with a kernel of this many px (they sit half a face inside its outline).")
    shadows: bool = Field(True, description="On a front without a seen handle, an enclosed horizontal unseen hole of handle size above the cameras' median height is the handle's scanning shadow (a bar seen from below hides the front behind it in every view); it types the joint (wall-cabinet flaps), it does not cut cells.")
    shadow_min_thick: float = Field(0.03, ge=0, description="A handle's scanning shadow is at least this tall (m).")
    proud_layer: float = Field(0.03, ge=0, description="Bars are also read on a second orthophoto of each plane, fused this far (m) in front of it from the same views in the same pass, where a bar standing that far proud (bar handles stand 2-4 cm off their fronts) is painted in its own place by every view: on the plane, views looking down at different angles paint a proud bar at different heights and the fusion keeps pieces of it too short for a bar (dark fronts whose white bars return no depth). A bar found there is added ... 0: off.")
    proud_gain: float = Field(2.0, ge=1, description="... where it stands out from its background (colour distance) at least this many times more than on the plane, and on the plane by the plane's threshold too: parallax smears a proud bar on the plane and sharpens it in front, a seam or an edge is sharpest on the plane, and the floor or a worktop seen past the plane's edge through the layer is not on the plane at all ...")
    proud_contrast: float = Field(1.2, ge=0, description="... by at least this colour distance from its background on the layer (1: the plane's mean brightness): what the layer sees past a plane's edge or along a front's bottom edge (a plinth's recess, the floor) stood out there by 0.3-0.96 on the dark tuning scenes, the bars the plane smeared by 1.47-2.0 ...")
    proud_margin: float = Field(0.05, ge=0, description="... at least this far (m) inside the plane's coverage: nearer its edge, views look past the plane through the layer (a plinth's recess, the floor, a worktop's underside) ...")
    proud_near: float = Field(0.05, ge=0, description="... and its box farther than this (m) from every handle's box found on the plane or kept before it (the same bar, smeared), strongest first.")
    knobs: bool = Field(True, description="Knobs are handles too: a compact blob (knob_size both ways, at most knob_aspect long for its width, filling knob_min_fill of its box) found like a bar, kept when it is part of a pattern (knob_pair). A sideboard or chest with knobs showed no bar, so its stacked drawers had no handle to split them apart, and a knob's side types a door's hinge (on a low front a centred one marks a drawer).")
    knob_size: tuple[float, float] = Field((0.025, 0.065), description="Both sides of a knob's blob (min, max; m): larger is a socket or a switch, smaller is noise.")
    knob_aspect: float = Field(1.6, ge=1, description="A knob's long side is at most this times its short side.")
    knob_min_fill: float = Field(0.7, ge=0, le=1, description="A knob's blob fills at least this share of its box (a round knob fills ~0.79; speckle on a dark front fills 0.2-0.6).")
    knob_pair: float = Field(0.02, ge=0, description="A knob is kept only when another knob on its plane, of a like size (knob_pair_size), has its centre within this (m) of the knob's row or column (0: every knob is kept). Knobs come in patterns (a column of drawers, a door pair, a row of sideboard fronts); the blobs on RedKitchen's fronts that pass as knobs stand alone or off each other's rows and columns.")
    knob_pair_size: float = Field(1.4, ge=1, description="... a like size: neither knob's sides more than this times the other's.")
    knob_pair_reach: float = Field(1.0, gt=0, description="... and the two at most this far apart (m): the knobs of one piece's fronts; blobs along a room's floor line meters apart are in one row by chance.")
    knob_panel_gap: float = Field(0.16, ge=0, description="Three or more like knobs in a row, each at most this far (m) from the next, are an appliance's control panel, no fronts' handles (0: off): no front is that narrow, and cutting between them halved the oven door below.")
    seam_share: float = Field(0.9, ge=0, le=1, description="A blob with at least this share of its pixels on straight seam evidence longer than any handle is a piece of a seam, not a handle (a fused seam is 3-5 px wide; where only part of it passes the contrast it is a bar-sized blob). At 0.5 a RedKitchen bar beside a door seam went too (every 4th frame: 6 / 4 -> 5 / 5). 0: off.")
    bar_plane_min: int = Field(2, ge=0, description="On a plane where at least this many handles stand out of the scan (bar_share of their pixels on the surface in front of the plane), colour-only handles are panel bevels and shading lines, not handles (0: off).")
    bar_share: float = Field(0.5, ge=0, le=1, description="... share of a handle's pixels on that surface that makes it a handle in the scan.")
    bar_reach: float = Field(0.0, ge=0, description="With bar_plane_min: only colour-only handles within this distance (m) of a bar go (0: every one on the plane).")
    bar_row: float = Field(0.0, ge=0, description="With bar_plane_min: a colour-only bar in line with a bar the scan holds (the same way, centre lines within this (m) across: parallax paints a proud bar a few cm off) stays: the next front's handle in the row or column (0: off).")
    bar_row_gap: float = Field(0.05, ge=0, description="... the two at least this far apart (m) along the line (a bevel or shadow line runs beside its bar, overlapping it).")
    pane_bar_reach: float = Field(0.1, ge=0, description="A glass pane is one door's: of the handles on its frame (their boxes inside the pane's box grown by this much, m; 0: off), colour-only ones go when a bar standing out of the scan (bar_share) is among them. A shaded patch on an oven's glass-door stile, read as a second handle beside its bar, cut the door in two along the pane's edge.")


class CellConfig(StageConfig):
    """Cells of a plane's orthophoto (perception/heuristic/front_cells.py) and which become fronts (image_fronts.py)."""

    min_side: float = Field(0.1, ge=0, description="No cell narrower than this (m).")
    max_split_depth: int = Field(6, ge=0, description="Guillotine split recursion depth.")
    pane_margin: float = Field(0.015, ge=0, description="No cut runs through a glass pane's core box (its lines holding at least half of its fullest line's pixels) grown by this (m): a pane lies inside one door, and painted with its frame's colour it still differs from the frame a little, so glass doors were cut along their panes' edges (0: panes do not bar cuts).")
    outline_step: float = Field(0.5, ge=0, description="Where the covered extent across a line jumps by this share of the cell (an L-shaped outline: a tall unit beside a base run), the cell is cut there first; 0: off.")
    knobs_any_side: bool = Field(True, description="A cell whose handles are all knobs may be cut at a horizontal seam with a knob on one side only: knobs that stand alone are not taken as handles (handles.knob_pair), so a wide drawer's single knob is missing and the seam under it must still be cut; the rule that asks for a handle on both sides is for glossy fronts' reflected edges, which are bars.")
    lone_knobs_block: bool = Field(True, description="No cut runs through a knob that stands alone (not taken as a handle, handles.knob_pair), as none runs through a handle: a chest's wide top drawer has one knob in its middle, right over the seam between the two drawers of each row below, and that seam's line ran on up through it and halved the top drawer.")
    edge_strip: float = Field(0.2, ge=0, description="Inside a cell holding handles a horizontal cut must leave a handle on both sides, except that a handle-less strip at most this tall (m) along the cell's top or bottom edge is cut off and is no front: a plinth, a worktop's or a carcass top's edge, which a slab over a dark unit takes in (0: such a cut is refused and the strip stays in the front).")
    seams_past_handles: bool = Field(True, description="Seams are read on the brightness with each handle's pixels filled in from the front beside it along the seam's direction (rows for horizontal seams, columns for vertical ones): a handle's colour is no seam, and a seam along a lip's edge, on a front's rows that the lip fills for most of their width, dipped only beside it. Off: handles' pixels count as they are.")
    edge_pull: float = Field(0.012, ge=0, description="A straight horizontal seam within this (m) of a horizontal bar's top edge is the seam that bar hangs from (an edge pull: a lip along a drawer's top edge), so the cut there may leave the handle below it alone and may run through that top band of the bar's box (not its bottom edge: under a bar lie its shadow and an oven window's rail), and a fainter seam there (seams.between_z, as between two handles) is cut too: stacked drawers with lips fused in pairs, as each lip touched the seam above it and the drawer above it showed no handle of its own (its lip on the piece's top outline). 0: no such cut.")
    groove_share: float = Field(0.3, ge=0, le=1, description="A cell with no seam line is cut along a groove: a band of lines at most groove_px wide whose coverage is under this share of the cell's median line coverage along its whole length, covered lines on both sides. On a 1 cm TSDF mesh the gap between two fronts is a 2-3 cm groove the surface leaves, unseen in the orthophoto too, so such a seam shows no dark line (0: off).")
    groove_px: int = Field(8, ge=1, description="... at most this many orthophoto px wide (3 cm at 4 mm).")
    groove_cover: float = Field(0.7, ge=0, le=1, description="... on a cell whose median line is covered at least this share of its length (on a patchy plane holes line up by chance).")
    pitch_tol: float = Field(0.1, ge=0, description="A cell holding a column of horizontal bars at one pitch (each step within this share of it), as tall as that many pitches or one more, with no seam between them, is cut into drawers of equal height on the pitch grid anchored at its edges, not halfway between the bars (edge pulls sit on the drawers' top edges; 0: off).")
    bar_pairs: bool = Field(True, description="A vertical bar at least twice the thinnest bar's thickness (handles.thickness) may be cut through its middle third, and each side then holds its part: two doors' bars either side of the seam where they meet, 1-3 cm apart, fuse into one blob in the colour and in a 1 cm TSDF mesh, and no cut ran through it, so a door pair with no other seam to cut stayed one front.")
    sliver_max: float = Field(0.13, ge=0, description="A cell at most this wide (m) between two cells of the same height, each at least sliver_ratio times wider, is the stile where two doors meet cut on both sides, not a front: two bar handles either side of the seam read as one handle (or a bright bar along it as two dark edges) and no cut may run through a handle, so the cuts fell on its sides; the sliver is cut down its middle (the seam between the bars; a dark line inside it is no help, the bars are dark lines too) and each half joins its neighbour with its half of the handle (glass tuning laser wall cabinets: a false 0.12 m door and four doors narrowed to IoU 0.5-0.6). 0: off.")
    sliver_ratio: float = Field(1.5, ge=1, description="... each neighbour at least this many times the sliver's width.")
    min_seen: float = Field(0.55, ge=0, le=1, description="Share of a cell the plane's faces must cover.")
    seen_rim: bool = Field(True, description="In a cell cut out on two sides or more whose handles sit inside its rim (clutter.handle_rim), the rim is left out of the share min_seen asks for too: on a fused scan a raised panel's bevels and the grooves between fronts are no surface of the plane, and the doors and drawers of a scene-synthesizer bank came out 45-53 % covered. Off: the whole cell.")
    min_tile_side: float = Field(0.25, ge=0, description="Handle-less cells smaller than this both ways are tiles, not fronts (m).")
    min_tiles: int = Field(3, ge=1, description="A plane is tiled (none of its handle-less cells is a front by its seams or as a piece's front) when at least this many of its covered cells are tile-sized (min_tile_side): at 1 a dishwasher's control strip, cut at its display into a tile-sized cell, made its drop door a tiling (free-standing tuning 308, 309).")
    strip_seams: bool = Field(False, description="A horizontal seam that cuts a strip at most edge_strip tall off a cell's top or bottom edge (a skirting board, a plinth, a cornice) counts as one of the larger side's seams (handleless_min_seams); off: it does not, so a plain wall between its skirting and a line under the ceiling is not cut out by seams (a false 1.2 x 2 m push-to-open door on the quarter-decimated TSDF wardrobe 6).")
    tile_edge_strips: bool = Field(False, description="A strip at most edge_strip tall along the top or bottom of a plane's coverage, cut into tile-sized pieces, counts towards min_tiles; off: it does not (a wardrobe's plinth cut in four by its door seams made the wardrobe a tiling).")
    handleless_min_seams: int = Field(2, ge=0, description="A handle-less cell cut out by this many straight seams (push-to-open fronts) is a front; 0: only beside a handled front.")
    stack_min: int = Field(3, ge=0, description="A handle-less cell in a column of at least this many door/drawer-sized cells stacked on one another, each as wide as the next (a drawer pedestal or chest with edge pulls or no handles), is a front; 0: off.")
    single_cut: bool = Field(True, description="A handle-less cell cut on one side only (its other sides the plane's outline: the end of a row, the top drawer of a pedestal) is a front when it stands in a stack (stack_min), beside a front kept by the other rules (same rows or same columns), or on a piece's front (piece_max_w); off: such cells are never fronts.")
    piece_max_w: float = Field(2.0, ge=0, description="A plane whose covered outline is at most this wide (m), at most fronts.max_h tall and filled to piece_fill, holding no front with a handle, is the front of one piece standing free (a fridge, a push-to-open cabinet): its handle-less cells cut on at least one side are its fronts; 0: off.")
    piece_behind: bool = Field(True, description="A piece's plane has scan surface behind it (room_wall.behind_share of the scan more than room_wall.depth behind, as the outer-wall test reads it): a piece stands in the room, so its carcass and the room around it lie behind its front; a stretch of outer wall seen between furniture does not (off: any plane shaped like a piece is one).")
    piece_fill: float = Field(0.6, ge=0, le=1, description="... share of the covered outline's box the plane's surface covers (a front is a rectangle, its TSDF edges ragged: a fridge's 0.71; a wall behind furniture is a box with holes: 0.22-0.32 on appliance scene 308).")
    piece_seen: float = Field(0.8, ge=0, le=1, description="... and the views see at least this share of the plane's surface (its coverage; a pixel within image.seen_reach of a seen one counts, as the depth-edge erosion takes every view's outline off, a glass door's frame included): a piece's side or back behind a chair or against a wall is held whole by a laser scan but little seen, and the edge of what hides it cut it into a 'front' (free-standing tuning, seen pixels alone: a sideboard's side 0.31, a chest freezer's side 0.72 (above 0.8 within the reach); true pieces' fronts 0.94 and more). 0: off.")
    piece_front_share: float = Field(0.5, ge=0, le=1, description="... and its handle-less fronts cover at least this share of the plane's surface: a piece is made of its fronts (fridge doors 0.9+, a dishwasher's door under its control strip 0.85); a washing machine's control strip over a porthole that is no plane is 0.2 of its front (free-standing tuning 309). 0: off.")
    mesh_split_seams: bool = Field(True, description="A mesh front holding two or more image fronts cut out by straight seams (cells.handleless_min_seams, on an untiled plane) is several fronts the mesh could not tell apart, as with two fronts with handles; off: only fronts with handles count.")


class ClutterConfig(StageConfig):
    """Cluttered cells are no fronts (perception/heuristic/image_fronts.py): posters, tiles, shelves."""

    max_share: float = Field(0.18, ge=0, le=1, description="Share of a cell's pixels off its local background above which it is clutter (posters, tiles, shelves).")
    max_share_handle: float = Field(0.3, ge=0, le=1, description="The same share for a cell holding a handle (raised-panel doors shade their own faces; a handle is evidence of a front); never below max_share.")
    handle_rim: float = Field(0.03, ge=0, description="In a cell holding a handle, the band this wide (m) along its edges is left out of the clutter share: a front's seams, a raised panel's bevel ring and a neighbour's colour bleeding over the seam lie there, and on small raised-panel doors (0.3 m) that band alone was a third of the cell (scene-synthesizer kitchens); a poster's or a shelf's clutter fills the middle. 0: the whole cell.")
    cell_median: bool = Field(True, description="A pixel is clutter only when it is also off the cell's own median colour (a band along an edge shared with a front of another colour is not).")
    median_min_px: int = Field(50, ge=0, description="... judged so only on cells with at least this many seen pixels outside the line structure.")
    line_min_len: float = Field(0.15, ge=0, description="Straight horizontal/vertical lines at least this long (m) are a front's structure (shaker frames, tile joints), not clutter; 0 counts them.")
    line_max_width: float = Field(0.02, ge=0, description="... and at most this thick (m).")


# the earlier flat keys of perception.heuristic -> their section and name now (one place: the validator
# below names the new key when a config still gives an old one)
RENAMED: dict[str, str] = {
    "facet_weld_m": "facets.weld_m",
    "facet_max_angle_deg": "facets.max_angle_deg",
    "render_scale": "render.scale",
    "min_mask_px": "render.min_mask_px",
    "n_probe": "probe.frames",
    "probe_view_px": "probe.view_px",
    "probe_min_views": "probe.min_views",
    "probe_min_px": "probe.min_px",
    "image_fronts": "image.enabled",
    "texture_factor": "image.texture_factor",
    "face_depth": "image.face_depth",
    "outline_fill_px": "image.outline_fill_px",
    "plain_floor_gap": "image.plain_floor_gap",
    "floor_min_area": "floor.min_area",
    "drawer_max_top": "reach.drawer_max_top",
    "splashback": "splashback.enabled",
    "splashback_min_z": "splashback.min_z",
    "splashback_band": "splashback.band",
    "splashback_reach": "splashback.reach",
    "splashback_cover": "splashback.cover",
    "room_wall": "room_wall.enabled",
    "room_wall_behind_share": "room_wall.behind_share",
    "room_wall_depth": "room_wall.depth",
    "room_wall_min_area": "room_wall.min_area",
    "room_door_min_h": "room_wall.door_min_h",
    "room_door_w": "room_wall.door_w",
    "room_door_floor_gap": "room_wall.door_floor_gap",
    "sliding_track_offset": "sliding.track_offset",
    "sliding_max_overlap": "sliding.max_overlap",
    "sliding_max_gap": "sliding.max_gap",
    "sliding_min_height_overlap": "sliding.min_height_overlap",
    "sliding_min_parallel": "sliding.min_parallel",
    "plane_offset_tol": "planes.offset_tol",
    "plane_angle_tol_deg": "planes.angle_tol_deg",
    "plane_refit_deg": "planes.refit_deg",
    "plane_refit_min_gain": "planes.refit_min_gain",
    "min_plane_area": "planes.min_area",
    "plane_cell": "planes.cell",
    "plane_min_fragment_area": "planes.min_fragment_area",
    "ortho_resolution": "ortho.resolution",
    "ortho_max_side_px": "ortho.max_side_px",
    "max_views": "ortho.max_views",
    "ortho_min_cos": "ortho.min_cos",
    "ortho_render_scale": "ortho.render_scale",
    "ortho_erode_px": "ortho.erode_px",
    "ortho_edge_jump": "ortho.edge_jump",
    "ortho_depth_tol": "ortho.depth_tol",
    "ortho_margin": "ortho.margin",
    "calibrate_colour": "calibration.enabled",
    "calib_scale_range": "calibration.scale_range",
    "calib_shift_range_px": "calibration.shift_range_px",
    "calib_min_gain": "calibration.min_gain",
    "register_sigmas_px": "registration.sigmas_px",
    "register_prior_scale": "registration.prior_scale",
    "register_prior_shift_px": "registration.prior_shift_px",
    "seam_contrast": "seams.contrast",
    "seam_span": "seams.span",
    "seam_prominence": "seams.prominence",
    "seam_prominence_h": "seams.prominence_h",
    "seam_z": "seams.dip_z",
    "step_contrast": "seams.step_contrast",
    "step_z": "seams.step_z",
    "step_over_dip": "seams.step_over_dip",
    "handle_contrast": "handles.contrast",
    "handle_len": "handles.length",
    "handle_thick": "handles.thickness",
    "handle_aspect": "handles.aspect",
    "handle_background_win": "handles.background_win",
    "handle_outline_margin": "handles.outline_margin",
    "handle_side_cover": "handles.side_cover",
    "handle_shadows": "handles.shadows",
    "protrusion_depth": "handles.protrusion_depth",
    "protrusion_from_surface": "handles.protrusion_from_surface",
    "min_front_side": "cells.min_side",
    "max_split_depth": "cells.max_split_depth",
    "outline_step": "cells.outline_step",
    "cell_min_seen": "cells.min_seen",
    "min_tile_side": "cells.min_tile_side",
    "handleless_min_seams": "cells.handleless_min_seams",
    "max_clutter": "clutter.max_share",
    "max_clutter_handle": "clutter.max_share_handle",
    "clutter_cell_median": "clutter.cell_median",
    "clutter_line_min_len": "clutter.line_min_len",
    "clutter_line_max_width": "clutter.line_max_width",
}


class PortholeConfig(StageConfig):
    """Round doors (washing machines, dryers): a ring standing proud of a plane (perception/heuristic/portholes.py)."""

    enabled: bool = Field(True, description="A ring of surface standing handles.protrusion_depth proud of a plane, all round a circle of a door's size with nothing proud inside, is a round door hinged at a side; the cells its plane's fronts would cover are replaced by it (off: the plate around it is cut into cells as any plane).")
    diameter: tuple[float, float] = Field((0.3, 0.6), description="The ring's outer diameter (min, max; m): washing machine and dryer doors are 0.4-0.5 m.")
    max_aspect: float = Field(1.25, ge=1, description="Its box is at most this much wider than tall or the other way (a round ring, seen straight).")
    band: tuple[float, float] = Field((0.55, 1.15), description="Its pixels lie within this band of the radius from the box's centre ...")
    ring_share: float = Field(0.85, ge=0, le=1, description="... this share of them at least (a square frame has 43 % of its outline beyond 1.15 of its half side) ...")
    sectors: float = Field(0.75, ge=0, le=1, description="... reaching this share of the sectors round the centre (a fused ring breaks in places) ...")
    inner: float = Field(0.45, ge=0, le=1, description="... and the disc within this share of the radius ...")
    inner_max: float = Field(0.1, ge=0, le=1, description="... is at most this share proud (the glass bowl is no surface; a round boss or a clock is a filled disc).")
    face_depth: tuple[float, float] = Field((-0.02, 0.12), description="Faces this far behind/in front of the plane are the door's (m): its ring and bowl stand up to 10 cm proud of the plate.")
    plate_gap: float = Field(0.15, ge=0, description="A front as wide as the door within this (m) above or below it is a strip of the appliance's plate (cut by the door's and the control panel's edges; the panel's knob may read as a handle), no front.")
    bar_cuts: bool = Field(True, description="No cell cut runs through a porthole door's core (the lines holding at least half of its widest line: |offset| <= 0.87 of the radius): its glass bowl is a hole in the plate's coverage, and the splitter took the hole's side for the corner of an L-shaped outline and cut the plate, and the detergent drawer above the door, in two (off: portholes are found after the split and only replace the cells they cover).")


class AgreementConfig(StageConfig):
    """Fronts the views agree on (perception/heuristic/view_agreement.py): the fronts are found again on
    interleaved subsets of the frames, and a front no subset finds again is dropped."""

    subsets: int = Field(0, ge=0, description="Opt-in (0: off; measured at 3). The selected frames are dealt into this many interleaved subsets (every n-th frame from each offset) and the fronts found again on each; a front that fewer than min_runs subsets hold (min_iou) came from one mixture of views (a blob only some views paint, a cut one occluder's edge made), not from the scan. RedKitchen, 100k-face copy: 8 / 2 -> 8 / 1 found / false; costs a perception pass per subset on a third of the frames.")
    min_iou: float = Field(0.3, ge=0, le=1, description="A subset holds a front when one of its fronts overlaps it at this rectangle IoU (on the same plane: facing alike within plane_cos, centres within plane_gap along the normal); a true front found again on fewer views is cut a little differently (RedKitchen's fronts: 0.42-0.99 in at least one subset), an artefact is not found at all (0.00-0.15).")
    min_runs: int = Field(1, ge=1, description="... a front is kept when at least this many subsets hold it.")
    min_frames: int = Field(10, ge=1, description="Each subset holds at least this many frames, else there is no agreement test (too few views to find a front on).")
    plane_cos: float = Field(0.94, ge=0, le=1, description="Two fronts lie on one plane when their normals' dot product is at least this (about 20 degrees) ...")
    plane_gap: float = Field(0.05, ge=0, description="... and their centres lie within this along the normal (m).")


class HeuristicConfig(StageConfig):
    """The weight-free heuristic: planar facets and fronts on the scan mesh, per-frame renders, and the
    image path (fronts found in the colour frames: seams, handles) and sliding-door pairs."""

    facets: FacetConfig = Field(default_factory=FacetConfig, description="Planar facets of the scan mesh.")
    probe: ProbeConfig = Field(default_factory=ProbeConfig, description="Which facets the cameras see.")
    render: RenderConfig = Field(default_factory=RenderConfig, description="Per-frame front renders (masks).")
    fronts: FrontRulesConfig = Field(default_factory=FrontRulesConfig, description="Front rules on the scan mesh.")
    floor: FloorConfig = Field(default_factory=FloorConfig, description="The floor's height.")
    reach: ReachConfig = Field(default_factory=ReachConfig, description="Drawers are within reach.")
    lids: LidConfig = Field(default_factory=LidConfig, description="A chest's front with a bar at its top is the lid's lip.")
    splashback: SplashbackConfig = Field(default_factory=SplashbackConfig, description="Splash-back above a worktop is no front.")
    room_wall: RoomWallConfig = Field(default_factory=RoomWallConfig, description="Only room doors open on the room's outer walls.")
    sliding: SlidingConfig = Field(default_factory=SlidingConfig, description="Sliding-door pairs.")
    image: ImageConfig = Field(default_factory=ImageConfig, description="Fronts found in the colour frames.")
    planes: PlanesConfig = Field(default_factory=PlanesConfig, description="Image path: large vertical planes of the mesh.")
    ortho: OrthoConfig = Field(default_factory=OrthoConfig, description="Image path: fused plane orthophotos.")
    calibration: CalibrationConfig = Field(default_factory=CalibrationConfig, description="Image path: colour self-calibration.")
    registration: RegistrationConfig = Field(default_factory=RegistrationConfig, description="Image path: per-view colour registration (opt-in).")
    seams: SeamConfig = Field(default_factory=SeamConfig, description="Image path: seams between fronts.")
    lines: LineConfig = Field(default_factory=LineConfig, description="Image path: seams supported by learned line segments (opt-in).")
    handles: HandleConfig = Field(default_factory=HandleConfig, description="Image path: handles.")
    cells: CellConfig = Field(default_factory=CellConfig, description="Image path: cells and which become fronts.")
    portholes: PortholeConfig = Field(default_factory=PortholeConfig, description="Image path: round doors from a ring standing proud of a plane.")
    clutter: ClutterConfig = Field(default_factory=ClutterConfig, description="Image path: cluttered cells are no fronts.")
    agreement: AgreementConfig = Field(default_factory=AgreementConfig, description="Fronts found again on subsets of the frames (opt-in).")

    @model_validator(mode="before")
    @classmethod
    def _renamed_keys(cls, data: Any) -> Any:
        """A key of the earlier flat layout gets its new name in the error, not just 'extra forbidden'."""
        if isinstance(data, dict):
            # 'splashback' and 'room_wall' are sections now: only their old boolean form is the old key
            old = [k for k in RENAMED if k in data and not (k in cls.model_fields and isinstance(data[k], dict | StageConfig))]
            if old:
                raise ValueError("; ".join(f"perception.heuristic.{k} is now perception.heuristic.{RENAMED[k]}" for k in old))
        return data
