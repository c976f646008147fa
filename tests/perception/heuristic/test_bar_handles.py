"""Handles the scan holds as bars outrank colour-only blobs on their plane (front_cells.bars_outrank_colour)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.perception.heuristic.front_cells import Handle, bars_outrank_colour, find_handles, in_line_with, split_cells
from tests.perception.heuristic.flat_orthos import flat_ortho, oven_door_image


def _handle(c0: int, r0: int, c1: int, r1: int) -> Handle:
    rr, cc = np.mgrid[r0:r1, c0:c1]
    return Handle((c0, r0, c1, r1), c1 - c0 >= r1 - r0, np.stack([cc.ravel(), rr.ravel()], 1))


def test_bars_outrank_colour_by_hand() -> None:
    """Three handles on a 20 x 20 px grid: A (4 px, all on bars), B (4 px, 2 on bars: share 0.5), C (4 px, none).
    With min_bars 2 and share 0.5, A and B stand out of the scan and C goes; with min_bars 3 only two stand
    out, so all three stay; min_bars 0 is off; share 0.6 leaves B colour-only, one bar, all stay."""
    bars = np.zeros((20, 20), bool)
    a, b, c = _handle(0, 0, 4, 1), _handle(0, 5, 4, 6), _handle(0, 10, 4, 11)
    bars[0, 0:4] = True
    bars[5, 0:2] = True
    assert bars_outrank_colour([a, b, c], bars, 2, 0.5) == [a, b]
    assert bars_outrank_colour([a, b, c], bars, 3, 0.5) == [a, b, c]
    assert bars_outrank_colour([a, b, c], bars, 0, 0.5) == [a, b, c]
    assert bars_outrank_colour([a, b, c], bars, 2, 0.6) == [a, b, c]
    assert bars_outrank_colour([a, b, c], bars, 1, 0.6) == [a]  # A alone stands out: one is enough at min_bars 1


def test_bars_outrank_colour_only_near_a_bar() -> None:
    """Bars A (rows 0) and B (row 5) on cols 0-3; colour-only C at row 10 (4 px below B's box: rows 6-9 lie
    between) and D at row 40 (34 px below). With reach 5 px only C goes (gap 4 <= 5); D, 34 px from B,
    stays; with reach 4 C still goes (4 <= 4), with reach 3 it stays; reach 0 drops both, as the plane-wide
    rule does."""
    bars = np.zeros((50, 20), bool)
    a, b = _handle(0, 0, 4, 1), _handle(0, 5, 4, 6)
    c, d = _handle(0, 10, 4, 11), _handle(0, 40, 4, 41)
    bars[0, 0:4] = True
    bars[5, 0:4] = True
    assert bars_outrank_colour([a, b, c, d], bars, 2, 0.5, 5.0) == [a, b, d]
    assert bars_outrank_colour([a, b, c, d], bars, 2, 0.5, 4.0) == [a, b, d]
    assert bars_outrank_colour([a, b, c, d], bars, 2, 0.5, 3.0) == [a, b, c, d]
    assert bars_outrank_colour([a, b, c, d], bars, 2, 0.5, 0.0) == [a, b]


def test_colour_bar_in_line_with_a_scan_bar_stays() -> None:
    """A row of drawers: scan bars A (cols 0-39, row 20) and B (cols 60-99, row 20); boxes are (c0, r0, c1, r1) with
    c1, r1 past the last pixel, so a bar's centre row is 20.5. Colour-only C (cols 120-159, rows 22-23: centre 23,
    2.5 px off, its box 120 - 100 = 20 px from B's along the row), a bevel line D under A (cols 0-39, row 26:
    centre 26.5, 6 px off, overlapping A along) and E far off the row (cols 120-159, row 40: 20 px off). With ``row_px`` 3 and ``row_gap_px`` 5: C stays (2.5 <= 3, gap 21 >= 5), D goes (it
    overlaps A and B along: gap < 0; and 5.5 > 3 across), E goes. ``row_px`` 2: C goes as well (2.5 > 2);
    ``row_px`` 0: the plane-wide rule, every colour-only bar goes. A vertical colour bar in that row does not
    line up with horizontal bars; nor does a bar more than twice as long (cols 120-219)."""
    bars = np.zeros((60, 240), bool)
    a, b = _handle(0, 20, 40, 21), _handle(60, 20, 100, 21)
    bars[20, 0:100] = True
    c, d, e = _handle(120, 22, 160, 24), _handle(0, 26, 40, 27), _handle(120, 40, 160, 41)
    assert bars_outrank_colour([a, b, c, d, e], bars, 2, 0.5, 0.0, 3.0, 5.0) == [a, b, c]
    assert bars_outrank_colour([a, b, c, d, e], bars, 2, 0.5, 0.0, 2.0, 5.0) == [a, b]
    assert bars_outrank_colour([a, b, c, d, e], bars, 2, 0.5) == [a, b]
    upright, long_ = _handle(120, 10, 122, 40), _handle(120, 20, 220, 21)
    assert not in_line_with(upright, [a, b], 30.0, 5.0)
    assert not in_line_with(long_, [a, b], 3.0, 5.0)  # 100 px against 40: more than twice as long
    assert in_line_with(c, [b], 3.0, 20.0) and not in_line_with(c, [b], 3.0, 21.0)  # 20 px from B
    assert in_line_with(c, [a, b], 3.0, 21.0)  # ... and 120 - 40 = 80 px from A


def _two_raised_panel_doors() -> tuple[np.ndarray, np.ndarray]:
    """A 0.8 x 0.7 m plane (200 x 175 px at 4 mm) of two doors side by side, each with a pale vertical bar
    handle 16 x 1.6 cm that stands out of the scan (cols 85-88 and 111-114, rows 40-79), and a dark bevel line
    26 x 2 cm along its panel's bottom (rows 150-154; cols 15-79 and 120-184) that only the colour shows."""
    rng = np.random.default_rng(3)
    img = np.full((175, 200, 3), 0.5, np.float32) + rng.normal(0, 0.003, (175, 200, 3)).astype(np.float32)
    bars = np.zeros((175, 200), bool)
    for c0 in (85, 111):
        img[40:80, c0:c0 + 4] = 0.9
        bars[40:80, c0:c0 + 4] = True
    img[150:155, 15:80] = 0.2
    img[150:155, 120:185] = 0.2
    return img, bars


def test_bevel_lines_do_not_cut_doors_beside_bar_handles() -> None:
    """The two doors of ``_two_raised_panel_doors``. Read by colour alone, each bevel line is a 26 x 2 cm bar
    (a handle's size) and the plane holds four handles, so the split leaves each door's bevel in a cell of
    its own (more than two cells). With the bars outranking colour, the two bars are the handles and the
    plane is cut once, between them: two cells, one handle each."""
    img, bars = _two_raised_panel_doors()
    o = flat_ortho(img)
    cov = np.ones(bars.shape, bool)
    off = HeuristicConfig(handles={"bar_plane_min": 0})
    on = HeuristicConfig()
    colour = find_handles(o, cov, off, protrusion=bars)
    assert len(colour) == 4
    assert len(split_cells(o, cov, colour, off)) > 2
    kept = find_handles(o, cov, on, protrusion=bars)
    assert len(kept) == 2 and not any(h.horizontal for h in kept)
    cells = split_cells(o, cov, kept, on)
    assert len(cells) == 2 and [len(c.handles) for c in cells] == [1, 1]
    assert 89 <= min(c.c1 for c in cells) <= 111


def test_colour_handles_stay_where_no_bar_stands_out() -> None:
    """The same plane with one bar left in the scan (a decimated or a real scan that lost the other): under
    bar_plane_min (2) bars, the colour is all the plane shows of its handles, and all four stay."""
    img, bars = _two_raised_panel_doors()
    bars[:, 100:] = False
    o = flat_ortho(img)
    assert len(find_handles(o, np.ones(bars.shape, bool), HeuristicConfig(), protrusion=bars)) == 4


def test_a_shaded_stile_cuts_an_oven_door_unless_one_bar_outranks_it() -> None:
    """An oven's glass door, 0.56 x 0.8 m (140 x 200 px at 4 mm): its bar on the top rail stands out of the scan
    (rows 30-38, cols 21-111); the pane's edge is a dark line 2 px wide (rows 48-49, cols 30-122; the pane
    itself painted its frame's colour, as fill_panes does) and a shaded patch 3.6 x 13.6 cm on the left stile
    (rows 138-171, cols 11-19) reads as a vertical handle by colour. At the default bar_plane_min (2) the patch
    is a second handle and the splitter cuts the door between the two (glass tuning 323, 324: a 13 cm "drawer"
    over the door); at 1 the bar is the door's one handle and the door one cell (measured, not the default:
    held-apart dark lost two parts with it)."""
    img, bars = oven_door_image()
    o = flat_ortho(img)
    cov = np.ones(bars.shape, bool)
    both = find_handles(o, cov, HeuristicConfig(), protrusion=bars)
    assert sorted(h.box[:2] for h in both) == [(11, 138), (21, 30)]
    assert len(split_cells(o, cov, both, HeuristicConfig())) == 2
    one_bar = HeuristicConfig(handles={"bar_plane_min": 1})
    one = find_handles(o, cov, one_bar, protrusion=bars)
    assert [h.box[:2] for h in one] == [(21, 30)]
    assert len(split_cells(o, cov, one, one_bar)) == 1


def _detergent_drawer() -> tuple[np.ndarray, np.ndarray]:
    """A white plate 0.6 x 0.4 m (150 x 100 px): a drawer's lip, a bar 12.4 x 2.4 cm in the scan (rows 40-45,
    cols 30-60), the dark colour of its top face right above it (rows 34-39, cols 26-64), and the protrusion
    the local surface reads along the proud drawer's side and bottom corner 3 px right of the lip (rows
    40-75, cols 64-71, and rows 70-75, cols 50-71: an L 8.8 x 14.4 cm, as on a scanned washing machine).
    Joined by the blob's row closing, lip, top face and L make one blob 46 x 42 px: no bar, no knob."""
    rng = np.random.default_rng(7)
    img = np.full((100, 150, 3), 0.9, np.float32) + rng.normal(0, 0.003, (100, 150, 3)).astype(np.float32)
    bars = np.zeros((100, 150), bool)
    img[34:40, 26:65] = 0.2
    img[40:46, 30:61] = 0.5
    bars[40:46, 30:61] = True
    bars[40:76, 64:72] = True
    bars[70:76, 50:72] = True
    return img, bars


def test_a_mesh_bar_joined_to_other_blobs_is_still_a_handle() -> None:
    cfg = HeuristicConfig()
    img, bars = _detergent_drawer()
    o, cov = flat_ortho(img), np.ones(bars.shape, bool)
    off = cfg.model_copy(update={"handles": cfg.handles.model_copy(update={"mesh_bar_parts": False})})
    assert find_handles(o, cov, off, protrusion=bars) == []
    hs = find_handles(o, cov, cfg, protrusion=bars)
    assert [(h.box, h.horizontal, h.knob) for h in hs] == [((30, 40, 61, 46), True, False)]
    assert len(hs[0].pixels) == 6 * 31  # the lip's own pixels, not the top face's or the L's
