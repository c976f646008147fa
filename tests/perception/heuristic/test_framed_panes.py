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
