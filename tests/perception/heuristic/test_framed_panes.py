"""Glass panes on a plane's coverage grid: holes framed all round by a door-frame wide band of the
plane's surface count as covered; gaps, narrow rims, small and open holes do not (hand-made grids)."""

from __future__ import annotations

import numpy as np

from react3d_core.perception.heuristic.image_fronts import framed_panes

RES = 0.004  # m per orthophoto pixel


def grid_with_hole(rim_px: int, hole=(40, 60)) -> tuple[np.ndarray, tuple[slice, slice]]:
    """A covered 200 x 300 px plane with one hole of ``hole`` px (rows, cols), ``rim_px`` of coverage
    around it, uncovered beyond the rim (the plane's other content is far away)."""
    cov = np.zeros((200, 300), bool)
    r0, c0 = 60, 100
    sl = (slice(r0, r0 + hole[0]), slice(c0, c0 + hole[1]))
    cov[r0 - rim_px:r0 + hole[0] + rim_px, c0 - rim_px:c0 + hole[1] + rim_px] = True
    cov[sl] = False
    return cov, sl


def test_a_pane_framed_by_a_door_frame_is_filled_and_nothing_else():
    cov, sl = grid_with_hole(rim_px=15)  # 6 cm frame around a 16 x 24 cm pane
    out = framed_panes(cov, RES, frame=0.035, cover=0.9, min_area=0.01)
    want = np.zeros_like(cov)
    want[sl] = True
    assert np.array_equal(out, want)


def test_narrow_rims_small_holes_open_gaps_and_off_are_not_panes():
    cov, _ = grid_with_hole(rim_px=5)  # a 2 cm rim (a carcass board's edge around an open shelf)
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.01).any()
    cov, _ = grid_with_hole(rim_px=15, hole=(10, 20))  # 4 x 8 cm: below min_area (a handle's shadow)
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.01).any()
    cov = np.ones((200, 300), bool)
    cov[:, 148:151] = False  # a gap between two fronts, top to bottom: touches the border
    cov[50:150, 20:120] = False
    cov[50:150, 20:23] = True
    cov[140:150, 20:120] = True  # ... and a hole open to the plane's edge on one side
    cov[50:150, 0:20] = False
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.01).any()
    cov, _ = grid_with_hole(rim_px=15)
    assert not framed_panes(cov, RES, 0.0, 0.9, 0.01).any()  # frame 0: off


def test_a_handle_shadow_framed_by_its_front_is_no_pane():
    # a TSDF front with a vertical bar's scanning shadow: a 2.4 x 20 cm hole, the front all round it
    cov, sl = grid_with_hole(rim_px=40, hole=(50, 6))
    assert framed_panes(cov, RES, 0.035, 0.9, 0.0).any()  # framed all round: without a pane size it was filled
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.0, min_side=0.1).any()
    cov, sl = grid_with_hole(rim_px=15)  # a 16 x 24 cm pane stays one
    assert framed_panes(cov, RES, 0.035, 0.9, 0.01, min_side=0.1)[sl].all()


def test_a_pane_split_by_a_shelf_seen_through_it_is_one_pane_with_the_shelf_edge():
    cov, sl = grid_with_hole(rim_px=15, hole=(100, 60))  # a 40 x 24 cm pane (rows 60-160, cols 100-160) ...
    cov[140:145, 100:160] = True  # ... a shelf's edge 2 cm tall across it, 6 cm above its bottom rail
    upper, lower, shelf = (slice(60, 140), sl[1]), (slice(145, 160), sl[1]), (slice(140, 145), sl[1])
    one = framed_panes(cov, RES, 0.035, 0.9, 0.01)
    # the upper hole's band is 91 % covered (the shelf edge and the rails), the lower's only 86 %
    assert one[upper].all() and not one[lower].any()
    three = framed_panes(cov, RES, 0.035, 0.9, 0.01, rounds=3)
    assert three[upper].all() and three[lower].all() and not three[shelf].any()
    closed = framed_panes(cov, RES, 0.035, 0.9, 0.01, rounds=3, bar=0.02)
    want = np.zeros_like(cov)
    want[sl] = True
    assert np.array_equal(closed, want)  # the shelf's edge is part of the door; the frame is not a pane


def test_a_pane_is_painted_its_frames_colour_past_the_shaded_edge_and_counts_as_seen():
    from react3d_core.perception.heuristic.image_fronts import fill_panes
    from react3d_core.perception.heuristic.orthophoto import Orthophoto

    def ortho() -> Orthophoto:
        cov, sl = grid_with_hole(rim_px=20)
        color = np.zeros(cov.shape + (3,), np.float32)
        color[cov] = (0.6, 0.5, 0.4)  # the frame
        edge = np.zeros_like(cov)
        edge[55:105, 95:165] = True
        edge[sl] = False
        color[edge] = (0.2, 0.2, 0.2)  # its inner edge, 5 px (2 cm), shaded
        return Orthophoto(plane=None, color=color, n_views=np.where(cov, 4, 0).astype(np.int32),
                          u0=0.0, v_top=0.0, res=RES), sl

    o, sl = ortho()
    before = o.color.copy()
    panes = np.zeros(o.n_views.shape, bool)
    panes[sl] = True
    fill_panes(o, panes, frame=0.035, gap=0.02)
    assert np.allclose(o.color[sl], (0.6, 0.5, 0.4)) and (o.n_views[sl] == 4).all()
    assert np.array_equal(o.color[~panes], before[~panes])  # nothing else changes
    o, sl = ortho()
    fill_panes(o, panes, frame=0.035, gap=0.0)  # read right at the pane: the shaded edge wins the median
    assert np.allclose(o.color[sl], (0.2, 0.2, 0.2))


def test_a_ragged_framed_hole_is_no_pane():
    # a bar handle's scanning shadow on a TSDF drawer: 20 x 12 cm across, framed all round, but a blob
    cov, sl = grid_with_hole(rim_px=40, hole=(30, 50))
    cov[60:75, 100:125] = True  # a quarter of its box is surface again ...
    cov[80:90, 135:150] = True  # ... and a bite out of the other side: 65 % of the box is hole
    assert framed_panes(cov, RES, 0.035, 0.9, 0.01, min_side=0.1).any()  # without the fill test: a pane
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.01, min_side=0.1, min_fill=0.8).any()
    cov, sl = grid_with_hole(rim_px=15)
    assert framed_panes(cov, RES, 0.035, 0.9, 0.01, min_side=0.1, min_fill=0.8)[sl].all()  # a rectangle stays one


def test_a_frame_the_views_see_but_the_scan_holds_in_bits_frames_a_pane():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map
    # a TSDF glass door: the views see its whole 6 cm frame; the scan's flat surface holds the top rail
    # in 2 cm stretches 2 cm apart and the left stile's outer 4 cm only (the fused surface is ragged there)
    seen, sl = grid_with_hole(rim_px=15)
    cov = seen.copy()
    for c in range(85, 175, 10):
        cov[45:60, c:c + 5] = False
    cov[45:175, 95:100] = False
    assert not framed_panes(cov, RES, 0.035, 0.9, 0.01, min_side=0.1, min_fill=0.8).any()
    frame = pane_frame_map(cov, seen, RES, speck=0.0, gap=0.0, reach=0.035)
    assert np.array_equal(frame, seen)
    assert framed_panes(frame, RES, 0.035, 0.9, 0.01, min_side=0.1, min_fill=0.8)[sl].all()
    assert np.array_equal(pane_frame_map(cov, None, RES, 0.0, 0.0), cov)  # without the views: the scan alone


def test_specks_behind_the_glass_are_taken_off_and_a_broken_rail_is_closed():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map
    seen, sl = grid_with_hole(rim_px=15, hole=(100, 60))  # a 40 x 24 cm pane, 6 cm frame
    seen[100:104, 100:160] = True  # a shelf's front edge 1.6 cm tall seen across it at the plane's depth
    seen[120:124, 110:114] = True  # ... and a jar's rim, a 1.6 cm speck
    seen[45:60, 120:135] = False  # the top rail broken over 6 cm: the pane runs out into the open
    kw = dict(frame=0.035, cover=0.9, min_area=0.01, rounds=3, min_side=0.1, bar=0.02, min_fill=0.8)
    assert not framed_panes(pane_frame_map(seen, None, RES, speck=0.0, gap=0.0), RES, **kw).any()
    assert not framed_panes(pane_frame_map(seen, None, RES, speck=0.02, gap=0.0), RES, **kw).any()  # still open
    assert not framed_panes(pane_frame_map(seen, None, RES, speck=0.0, gap=0.08), RES, **kw)[sl].all()  # split
    panes = framed_panes(pane_frame_map(seen, None, RES, speck=0.02, gap=0.08), RES, **kw)
    want = np.zeros_like(seen)
    want[sl] = True
    assert np.array_equal(panes, want)  # one pane, the shelf's edge and the jar in it; the frame is none


def test_the_frame_map_keeps_an_open_shelfs_narrow_rim_and_a_gap_between_fronts_unframed():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map
    kw = dict(frame=0.035, cover=0.9, min_area=0.01, rounds=3, min_side=0.1, bar=0.02, min_fill=0.8)
    rim, _ = grid_with_hole(rim_px=5)  # a 2 cm carcass edge round an open shelf, seen by the views
    assert not framed_panes(pane_frame_map(rim, rim, RES, speck=0.02, gap=0.08), RES, **kw).any()
    fronts = np.ones((200, 300), bool)
    fronts[:, 148:151] = False  # a gap between two fronts, top to bottom
    fronts[60:160, 20:80] = False  # ... and a 24 x 40 cm opening cut into the plane's edge
    fronts[60:160, 0:20] = False
    assert not framed_panes(pane_frame_map(fronts, fronts, RES, speck=0.02, gap=0.08), RES, **kw).any()


def test_what_the_views_see_far_inside_a_pane_does_not_frame_it():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map
    # a laser scan's glass door: the scan holds the 6 cm frame; the views see books standing right
    # behind the glass, at the plane's depth, over the lower half of the pane, 4-8 cm in from the frame
    cov, sl = grid_with_hole(rim_px=15, hole=(100, 60))
    seen = cov.copy()
    seen[110:150, 110:150] = True
    kw = dict(frame=0.035, cover=0.9, min_area=0.01, rounds=3, min_side=0.1, bar=0.02, min_fill=0.8)
    assert not framed_panes(pane_frame_map(cov, seen, RES, speck=0.02, gap=0.08), RES, **kw)[sl].all()
    panes = framed_panes(pane_frame_map(cov, seen, RES, speck=0.02, gap=0.08, reach=0.035), RES, **kw)
    assert panes[sl].all()


def test_a_whole_scan_surface_frames_panes_alone():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map
    # a laser scan: the coverage holds 98 % of what the views see near it (a 2.4 cm shelf board behind
    # the glass, seen at the plane's depth, lies partly within reach of the stiles): the map is the
    # coverage as it is
    cov, sl = grid_with_hole(rim_px=15, hole=(100, 60))
    seen = cov.copy()
    seen[100:106, 100:160] = True
    assert np.array_equal(pane_frame_map(cov, seen, RES, 0.02, 0.08, reach=0.035, max_cover=0.9), cov)
    ragged = pane_frame_map(cov, seen, RES, 0.02, 0.08, reach=0.035, max_cover=1.0)  # no bound: joined
    assert ragged[100:106, 100:109].all() and not ragged[100:106, 112:148].any()


def _cupboard_without_top_rail(rail_px: int) -> tuple[np.ndarray, np.ndarray]:
    """A glass door on a TSDF plane (4 mm px): the views see its 6 cm stiles and bottom rail, the coverage
    holds a ragged 3 cm strip of each (rows 22-160: under 90 % of what the views see near it), and the
    views see a top rail ``rail_px`` tall from row 10 whose middle lies farther than their 3.5 cm reach
    from the coverage (it lies on the box's rounded top edge)."""
    cov = np.zeros((200, 140), bool)
    cov[22:160, 24:31] = cov[22:160, 109:116] = cov[149:156, 20:120] = True
    seen = np.zeros_like(cov)
    seen[10:160, 20:35] = seen[10:160, 105:120] = seen[145:160, 20:120] = True
    seen[10:10 + rail_px, 20:120] = True
    return cov, seen


def test_a_top_rail_the_views_see_at_the_planes_edge_frames_the_pane():
    from react3d_core.perception.heuristic.image_fronts import pane_frame_map, seen_rim

    cov, seen = _cupboard_without_top_rail(rail_px=13)  # a 5 cm rail

    def panes(rim: float, c: np.ndarray = cov, s: np.ndarray = seen) -> np.ndarray:
        framing = pane_frame_map(c, s, RES, 0.02, 0.08, 0.035, 0.9, rim)
        return framed_panes(framing, RES, 0.035, 0.9, 0.01, 3, 0.1, 0.02, 0.8)

    rim = seen_rim(seen, RES, 0.035)
    assert rim[10:19, 20:120].all() and not rim[19:140, 35:105].any() and rim[151:160, 20:120].all()
    assert not panes(0.0).any()  # the hole runs out over the top: no pane
    p = panes(0.035)
    assert p[60:140, 40:100].all() and not p[:15].any() and not p[:, :30].any()
    # a carcass board's edge (1.6 cm, thinner than pane_speck) above an open shelf frames nothing
    cov, seen = _cupboard_without_top_rail(rail_px=4)
    assert not panes(0.035, cov, seen).any()
