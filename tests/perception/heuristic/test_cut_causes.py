"""Where the image path cuts a plane into fronts and which handles it believes, on the mechanisms traced on
clean kitchens: a seam of stacked drawers that spans most of a run (not all of it), a drawer's seam just
inside the box of the handle below it, a front's own handle counted as clutter, a piece of a fused seam
taken for a handle."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import HeuristicConfig, SeamConfig
from react3d_core.perception.heuristic.front_cells import (Cell, Handle, _bar_seen_twice, _between, _dip_scores,
                                                           _split_handles, find_handles, split_cells)
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.image_fronts import VetoEvidence, _cluttered, _hardware
from tests.perception.heuristic.flat_orthos import flat_ortho


_ortho = flat_ortho


def test_line_dark_over_part_of_the_cell_is_no_straight_seam() -> None:
    """Rows 70 (dark over columns 0-299 of 500: stacked drawers' seam, 60 % of the run) and 140 (dark
    over all 500): each line's median over the whole cell is 0.8, a dip of 0.2 below the rows beside it;
    the MAD of the dips is 0, floored at 1e-3, so both score 200 without the piece rule. With it (pieces
    3 x min_px = 75 px: 500 // 75 = 6 pieces of 83-84 px) row 70 is plain in the last two pieces (columns
    333-499: a dip of 0 there, under piece_contrast), so it scores 0; row 140 dips in every piece and keeps 200."""
    g = np.ones((200, 500))
    g[70, :300] = 0.8
    g[140, :] = 0.8
    cov = np.ones(g.shape, bool)
    off = _dip_scores(g, cov, 1, 25, SeamConfig(piece_sides=0))
    on = _dip_scores(g, cov, 1, 25, SeamConfig())
    assert off[70] == pytest.approx(200.0) and off[140] == pytest.approx(200.0)
    assert on[70] == 0.0 and on[140] == pytest.approx(200.0)
    assert np.count_nonzero(on) == 1


def test_drawer_seams_beside_a_door_do_not_cut_it() -> None:
    """A 2.0 x 0.8 m run at 4 mm (200 x 500 px, a little noise): three stacked drawers over columns 0-299
    (seams 25 % dark at rows 66 and 133), a fainter seam (7 %) at column 300, a plain door over columns 301-499 (60 % / 40 %, as on
    clean kitchen 100). The door comes out as one cell over the whole height; without the piece rule the
    drawers' seams, whose line medians dip across the whole run, cut the door into three."""
    rng = np.random.default_rng(3)
    img = np.ones((200, 500, 3), np.float32) + rng.normal(0, 0.003, (200, 500, 3)).astype(np.float32)
    img[[66, 133], :300] *= 0.75
    img[:, 300] *= 0.93
    o = _ortho(img)
    cov = np.ones((200, 500), bool)

    def door_cells(cfg: HeuristicConfig) -> list[Cell]:
        return [c for c in split_cells(o, cov, [], cfg) if c.c0 > 290]

    door = door_cells(HeuristicConfig())
    assert len(door) == 1 and door[0].r0 == 0 and door[0].r1 == 200 and abs(door[0].c0 - 301) <= 2
    assert len(door_cells(HeuristicConfig(seams={"piece_sides": 0}))) == 3


def test_cut_between_stacked_handles_finds_the_seam_inside_a_handle_box() -> None:
    """A drawer handle (rows 20-25, centre 23) above a door handle whose box starts at row 55 (centre 82);
    the seam between drawer and door is at row 58, three rows inside the door handle's box. Between the
    boxes (rows 26-54) no line dips, nor has valley evidence, so the cut fell at their middle, row 40,
    halfway up the drawer; sought between the centres it is the seam."""
    g = np.ones((150, 100))
    g[58, :] = 0.85
    cov = np.ones(g.shape, bool)
    ev = np.zeros(g.shape, bool)
    p = SeamConfig()
    assert _between(g, ev, cov, 1, 26, 55, 25, p) == 40
    assert _between(g, ev, cov, 1, 26, 55, 25, p, centres=(23, 82)) == 58
    drawer = Handle((30, 20, 70, 26), True, np.zeros((0, 2), int))     # centre row 23
    door = Handle((80, 55, 86, 110), False, np.zeros((0, 2), int))     # centre row 82.5
    a, b = sorted(_split_handles(Cell(0, 0, 100, 150, [drawer, door]), ev, ev, cov, 25, (g, g), p), key=lambda c: c.r0)
    assert (a.r1, b.r0) == (58, 59) and a.handles == [drawer] and b.handles == [door]


def test_handles_are_cut_apart_clear_of_a_third_handle() -> None:
    """A drawer (rows 0-59, its bar at columns 70-150, rows 25-31) over two doors (rows 61-199, meeting at
    column 100, whose line runs on fainter up the drawer; handles at columns 20-25 and 175-180, rows 100-150).
    The handles spread 155 px across and 97 px up, so the first cut is sought between columns, between the
    left handle and the bar (centres 22 and 110, the widest gap): at the door seam, column 100, which has 30
    of the bar's 80 px on its left and 50 on its right (both over a quarter): it would halve the drawer and
    its bar. The cut between rows (the drawer's seam, row 60) runs through no handle, so it is taken first and
    the doors are cut apart under it; with the rule off the drawer is halved."""
    g = np.ones((200, 200))
    g[60, :] = 0.85
    g[61:, 100] = 0.85
    g[:60, 100] = 0.92  # the door seam's line runs on, fainter, up the drawer (its shading)
    cov = np.ones(g.shape, bool)
    ev = np.zeros(g.shape, bool)
    bar = Handle((70, 25, 150, 31), True, np.zeros((0, 2), int))
    left = Handle((20, 100, 25, 150), False, np.zeros((0, 2), int))
    right = Handle((175, 100, 180, 150), False, np.zeros((0, 2), int))
    cell = Cell(0, 0, 200, 200, [bar, left, right])
    cells = _split_handles(cell, ev, ev, cov, 25, (g, g), SeamConfig())
    boxes = sorted((c.c0, c.r0, c.c1, c.r1) for c in cells)
    assert boxes == [(0, 0, 200, 60), (0, 61, 100, 200), (101, 61, 200, 200)]
    assert [c.handles for c in sorted(cells, key=lambda c: (c.c0, c.r0))] == [[bar], [left], [right]]
    off = sorted((c.c0, c.r0, c.c1, c.r1) for c in _split_handles(cell, ev, ev, cov, 25, (g, g),
                                                                   SeamConfig(clear_of_handles=False)))
    assert off == [(0, 0, 100, 200), (101, 0, 200, 60), (101, 61, 200, 200)]


def test_a_bar_painted_at_two_heights_is_not_cut_apart() -> None:
    """One door (130 x 185 px, a little noise, no seam) whose bar the views painted at two heights: columns
    29-59 at rows 21-25 and columns 53-97 at rows 32-36 (RedKitchen's corner door). Their centres lie 31 px
    apart across and 11 px up, more than min_px (25) across, so the cell was cut side by side between them.
    They share columns 53-59 (7 > 2), so no vertical seam runs between them: one front. Bars sharing 2
    columns (29-54 and 53-97), or one bar above a knob, are still cut apart."""
    rng = np.random.default_rng(4)
    g = np.ones((185, 130)) + rng.normal(0, 0.003, (185, 130))
    cov = np.ones(g.shape, bool)
    ev = np.zeros(g.shape, bool)
    p = SeamConfig()
    upper = Handle((29, 21, 60, 26), True, np.zeros((0, 2), int))
    lower = Handle((53, 32, 98, 37), True, np.zeros((0, 2), int))
    assert _bar_seen_twice(upper, lower) and _bar_seen_twice(lower, upper)
    assert len(_split_handles(Cell(0, 0, 130, 185, [upper, lower]), ev, ev, cov, 25, (g, g), p)) == 1
    short = Handle((29, 21, 55, 26), True, np.zeros((0, 2), int))
    assert not _bar_seen_twice(short, lower)
    assert len(_split_handles(Cell(0, 0, 130, 185, [short, lower]), ev, ev, cov, 25, (g, g), p)) == 2
    knob = Handle((53, 32, 60, 39), True, np.zeros((0, 2), int), True)
    assert not _bar_seen_twice(upper, knob)


def test_a_fronts_own_handle_is_no_clutter() -> None:
    """A 0.4 x 0.18 m drawer (4 mm px: 100 x 45 px, colour 1.0) alone in the orthophoto, its 0.3 x 0.03 m bar
    handle (75 x 7 = 525 px, 11.7 %, colour 1.6) off the background and 7 % of the other pixels off too (315
    px dark, the worktop edge's shadow): 840 / 4500 = 18.7 % is over clutter.max_share 0.18, so the mesh front
    was vetoed; without its handle 315 / 4500 = 7 %."""
    h, w, res = 45, 100, 0.004
    img = np.ones((h, w, 3), np.float32)
    rr, cc = np.meshgrid(np.arange(10, 17), np.arange(12, 87), indexing="ij")
    img[rr, cc] = 1.6
    img[0:3, :] = 0.5                                       # 300 px ...
    img[3, :15] = 0.5                                       # ... + 15 = 315
    o = _ortho(img, res)
    handle = Handle((12, 10, 87, 17), True, np.stack([cc.ravel(), rr.ravel()], 1))
    f = Front(facet=0, handle_facets=[], center=np.array([0.2, 0.0, 0.09]), n_out=np.array([0.0, -1.0, 0.0]),
              u=np.array([1.0, 0.0, 0.0]), extent_u=(0.0, 0.4), extent_v=(0.0, 0.18), faces=np.zeros(0, np.int64))
    cfg = HeuristicConfig()
    none = np.zeros((h, w), bool)
    assert _cluttered(f, [o], [VetoEvidence(cfg.handles.contrast, _hardware(none, []))], cfg)
    assert not _cluttered(f, [o], [VetoEvidence(cfg.handles.contrast, _hardware(none, [handle]))], cfg)


def test_piece_of_a_fused_seam_is_no_handle() -> None:
    """A 0.8 x 0.8 m panel (4 mm px): a seam 4 px wide over the whole height, 5 % dark (below the handle
    contrast), 25 % dark over rows 120-179 (a 0.24 m x 16 mm dark bar there, as where the views of a fused
    seam disagree most), and a real bright bar 0.2 m x 2 cm 10 cm to its right. Without the seam rule both
    are handles; with it (90 % of a blob on straight seam evidence longer than any handle) only the bar."""
    h = w = 200
    rng = np.random.default_rng(5)
    img = np.ones((h, w, 3), np.float32) + rng.normal(0, 0.003, (h, w, 3)).astype(np.float32)
    img[:, 100:104] *= 0.95
    img[120:180, 100:104] *= 0.75 / 0.95
    img[60:110, 130:135] = 1.6
    o = _ortho(img)
    cov = np.ones((h, w), bool)
    off = find_handles(o, cov, HeuristicConfig(handles={"seam_share": 0.0}))
    on = find_handles(o, cov, HeuristicConfig())
    assert sorted(hd.box[0] // 10 for hd in off) == [10, 13]
    assert [hd.box[0] // 10 for hd in on] == [13]
