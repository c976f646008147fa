"""Versions of the weight-free perception backends, in one light module so the stage descriptor can
name them without importing the backends (Open3D, OpenCV)."""

# 2: frame-and-panel fronts, rims, drawer_max_h 0.45; 3: fronts from the colour frames; 4: sliding doors;
# 5: straight seams by line median, handle shadows filled, texture-adaptive clutter; 6: splash-back rule,
# colour steps beat weaker dark lines, line structure and the cell's own colour in the clutter test;
# 7: enclosed handle-shaped unseen holes are handles (wall-cabinet flaps), mirrored background border;
# 8: a cell holding a handle may be more cluttered (clutter.max_share_handle 0.3: raised-panel doors);
# 9: a handle-less image front reaching down to the floor is wall (image.plain_floor_gap);
# 10: a wide vertical plane's direction is refit from its faces' positions (planes.refit_deg)
# 11: handles in the mesh skip the colour opening (a 3-4 px bar fell apart) and are grown by 1 px
# 12: on the room's outer walls (no scan surface behind the plane) only room-door-shaped fronts stay,
#     typed as side-hinged doors (room_wall.enabled)
# 13: image cells are cut first at an L-shaped outline's corner (cells.outline_step); drawer-typed fronts
#     above 1.7 m are dropped (reach.drawer_max_top)
# 14: handles in the mesh stand out from the surface around them, not the fitted plane
#     (handles.protrusion_from_surface), and a handle has the plane's outline on both long sides (handles.side_cover)
# (per-view colour registration, registration.sigmas_px, is opt-in: off it changes nothing, and the
# configuration a run uses is part of the cache key)
# 15: holes in a plane's coverage framed all round by a door-frame wide band count as covered (glass
#     panes the scan lacks; image.pane_*)
# 16: a straight seam dips in every 0.3 m piece of its length (seams.piece_*), the cut between stacked
#     handles is sought between their centres, a front's own handles are no clutter in the mesh-front veto,
#     a blob lying on a long straight seam is no handle (handles.seam_share)
# 17: knobs are handles (handles.knobs: compact round blobs), and a knob types its front by where it sits
#     (fronts.knob_*: centred is a drawer's or a flap's, off-centre a door's opening edge); a handle-less strip
#     along a handled cell's top or bottom edge is cut off (cells.edge_strip: plinths, worktop edges)
# 18: the mesh-front veto judges a front against its own rectangle's background, by the plane's threshold,
#     with the surface standing out of the plane (handles in the mesh) left out
# 19: a modelled wall's own outer side (facing away, within room_wall.wall_back) is not surface behind it
# 20: only a knob-sized handle (fronts.knob_max_size) is typed by its place; a larger compact blob keeps the bar reading
# 21: pieces standing free in the room: slices through a turned surface are no planes and the faces no
#     plane explains vote again (planes.max_skew_deg, planes.revote_rounds); a plane faces the way its
#     faces' normals point (planes.normal_agree); handle-less cells stacked in a column are fronts
#     (cells.stack_min); chest lids (lids); surface within room_wall.wall_band behind a front is in its plane
# 22: handle-less cells cut on one side only (row ends, a pedestal's top drawer) are fronts in a stack or
#     beside a kept front (cells.single_cut); a small filled handle-less plane is a piece's front, its cut
#     cells fronts (cells.piece_*); a mesh front holding two seam-cut image fronts is replaced by them
#     (cells.mesh_split_seams); no flap or drop door is taller than fronts.flap_max_h; in a handle-less
#     cell a straight bright row is a seam (seams.ridges)
# 23: glass panes are on by default (image.pane_frame), pane-sized only (image.pane_min_side: handle shadows
#     are no panes), sought again with the panes found counted as frame and closed over shelf edges
#     (image.pane_rounds, image.pane_bar), and painted their frame's colour (image.pane_fill, image.pane_edge)
# 24: a scan's plane whose faces are coarser than image.rays_face_edge (a decimated scan; not a modelled
#     plane, image.modelled_share) reads its coverage and handles from rays, not its faces' centroids
# 25: a plane is tiled only with cells.min_tiles tile-sized cells (an appliance's control strip is no
#     tiling), and a piece's handle-less fronts cover cells.piece_front_share of its plane
# 26: a seam cutting an edge strip off a cell is no seam of the larger side (cells.strip_seams), a piece's
#     plane has scan surface behind it (cells.piece_behind): plain walls are no push-to-open fronts; and a
#     plinth or cornice strip cut into pieces is no tiling (cells.tile_edge_strips)
# 27: on a plane whose coverage holds under 90 % of what the views see near it, panes are sought on the
#     coverage joined with that, specks and thin strokes taken off and gaps in a frame closed
#     (image.pane_seen, pane_seen_reach, pane_seen_max_cover, pane_speck, pane_gap)
# 28: on a plane where at least two handles stand out of the scan, colour-only handle blobs are panel
#     bevels and shading lines, not handles (handles.bar_plane_min, bar_share)
# 29: a ring standing proud of a plane all round a door-sized circle is a porthole door hinged at a side; the
#     plane's cells covering it and its plate's handle-less strips over and under it are no fronts (portholes)
# 30: a colour-only handle with one long side on the plane's surface but seen by no view is the edge of what hides
#     the plane, not a handle (handles.hidden_side)
# 31: a piece's handle-less fronts need its plane seen: the views see cells.piece_seen of its coverage
# 32: panes count as covered in a cell's coverage test as well as in its cut (image.pane_cell_cover)
# 33: a piece is seen where its coverage lies within image.seen_reach of a seen pixel (a glass door's frame
#     between depth edges counted unseen, and a glass cabinet was no piece)
# 34: handles.hidden_side off by default (it cost RedKitchen three fronts)
# 35: a sliver cell between two wider cells of its rows is the stile where two doors meet: cut down its
#     middle into its neighbours, with its handle halves (cells.sliver_max)
# 36: fronts seen through a glass door (behind another plane's pane, within a cabinet's depth) are the
#     cabinet's inside, not fronts (image.glass_behind)
# 37: image.pane_seen_rim on (0.035): a TSDF glass door's top rail on the fused box's rounded edge frames its pane
# 38: knobs are handles by default, kept in patterns (pairs in a row or column; not a control panel's row);
#     two knobs side by side are cut apart only at a seam; a knob-only cell is cut with a knob on one side
# 39: no cut runs through a knob that stands alone (cells.lone_knobs_block)
# 40: each mask names the front it shows (Mask2D.instance), the same in every frame
# 41: seams are read with the handles' pixels filled in along them (cells.seams_past_handles), and a straight seam
#     just above a horizontal bar is the seam that edge pull hangs from: cut with the handle below it alone (cells.edge_pull)
# 42: opt-in, the vertical faces no plane explains vote last by normals averaged over their neighbours
#     (planes.smooth_rings: a piece turned from a TSDF scan's voxel grid), and such a plane's handle-less fronts are
#     no free-standing piece's; a band of lines the scan's
#     surface leaves along a whole cell is a seam (cells.groove_*); a wide vertical bar may be cut through its
#     middle, each side keeping its part (cells.bar_pairs: two doors' bars fused across the seam where they meet);
#     a column of bars at one pitch with no seam between them is cut on the pitch grid (cells.pitch_tol)
# 43: two knobs at one height by a cell's middle, with no seam between them, are a door pair's: cut at their
#     midpoint (seams.knob_pair_gap)
# 44: colour beside hidden scan surface is no handle again (handles.hidden_side), when the hidden surface also
#     reaches hidden_depth from it: what an occluder hides, not the strip a handle hides from oblique views
# 45: bars are also read on an orthophoto fused 3 cm in front of each plane (handles.proud_layer), where a
#     bar standing proud is painted in its own place by every view, not smeared by their parallax
# 46: colour-only handles on a glass pane's frame go when a bar standing out of the scan is on that frame
#     (handles.pane_bar_reach)
# 47: no cut runs through or along a glass pane (cells.pane_margin), panes are framed at 85 % of their band
#     (image.pane_frame_cover), the views' left and right plane edges may frame panes (image.pane_seen_rim_sides, opt-in),
#     and vertical planes from 0.05 m² are photographed (planes.min_area: a microwave's door around its window)
# 48: no cut runs through a porthole door's core (portholes.bar_cuts); the bar pieces the mesh alone holds in a
#     blob too thick for a handle are handles (handles.mesh_bar_parts: a detergent drawer's lip); a handle-less
#     front over a porthole's columns within plate_gap is the plate (the control panel beside the drawer)
# 49: a framed hole the scan holds a surface across, near the plane and facing out, is a solid panel, not glass
#     (image.pane_solid_share): it counts as the plane's coverage, seen in its own colours, and bars no cut
# 50: handles are cut apart clear of a third handle (seams.clear_of_handles: a drawer's bar over the seams of the
#     doors below); a cut-out front's rim (clutter.handle_rim) is left out of its clutter and coverage shares
#     (cells.seen_rim)
# 51: colour seen by few views is no handle (handles.few_views); bars up to 0.6 m (handles.length); a bar painted at
#     two heights is not cut apart; fronts level with the top of a run standing a worktop's depth in front of them
#     are splash-back (splashback.run_depth)
# (opt-in, off it changes nothing: the faces no offset peak took vote again, planes.residual_dip: a front set back
# a few cm beside a larger one, a microwave on its cabinet)
# 52: splash-back allows for the worktop's thickness above a run (splashback.worktop_rise), and a front with the
#     wall behind it (an appliance pushed back on the worktop) is no splash-back (splashback.wall_*)
# 53: seams supported by straight segments several views agree on cut cells by default, the segments found by
#     OpenCV's LSD on the grey image lifted by gamma 0.5 (lines.enabled, lines.detector lsd; no weights)
# (opt-in, off it changes nothing: a colour-only bar in line with a bar the scan holds stays, handles.bar_row)
HEURISTIC_VERSION = "53"
# 2: says "sliding" for GT prismatic joints in the part's front plane
ORACLE_VERSION = "2"
