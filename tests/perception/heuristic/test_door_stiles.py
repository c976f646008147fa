"""Where two doors meet: bar handles either side of the seam fuse into one blob, no cut may run through a
handle, so the cuts fell on the blob's sides and the stile between them became a sliver cell (a false
narrow door, both doors narrowed). The sliver is cut down its middle into its neighbours."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig, SeamConfig
from react3d_core.perception.heuristic.front_cells import Cell, Handle, _split_handles, merge_slivers, split_cells
from tests.perception.heuristic.flat_orthos import flat_ortho


def _bar(c0: int, c1: int, r0: int, r1: int) -> Handle:
    cols, rows = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
    return Handle((c0, r0, c1, r1), False, np.stack([cols.ravel(), rows.ravel()], 1))


def test_sliver_is_cut_down_its_middle_by_hand() -> None:
    """Cells [0, 100), [101, 131), [132, 232) over rows 0-150; the 30 px sliver holds a fused bar over
    columns 110-121. Its middle is column (101 + 131) // 2 = 116: the left door ends there, the right one
    starts at 117; the bar's columns 110-115 go left, 117-121 right (column 116 is the cut line)."""
    a, s, b = Cell(0, 0, 100, 150), Cell(101, 0, 131, 150, [_bar(110, 122, 20, 80)]), Cell(132, 0, 232, 150)
    out = merge_slivers([a, s, b], max_px=32, ratio=1.5)
    assert [(c.c0, c.c1) for c in out] == [(0, 116), (117, 232)]
    (left,), (right,) = out[0].handles, out[1].handles
    assert left.box == (110, 20, 116, 80) and right.box == (117, 20, 122, 80)
    assert len(left.pixels) == 6 * 60 and len(right.pixels) == 5 * 60


def test_no_sliver_at_a_planes_end_or_beside_a_narrow_cell() -> None:
    """A narrow cell with a neighbour on one side only (the plane's end), or beside a cell less than
    ratio times wider, or one taller than its neighbours (another row of fronts), stays as it is."""
    end = [Cell(0, 0, 30, 150), Cell(31, 0, 131, 150)]
    assert [(c.c0, c.c1) for c in merge_slivers(end, 32, 1.5)] == [(0, 30), (31, 131)]
    narrow = [Cell(0, 0, 40, 150), Cell(41, 0, 71, 150), Cell(72, 0, 172, 150)]   # 40 < 1.5 x 30
    assert len(merge_slivers(narrow, 32, 1.5)) == 3
    rows = [Cell(0, 0, 100, 80), Cell(101, 0, 131, 150), Cell(132, 0, 232, 150)]
    assert len(merge_slivers(rows, 32, 1.5)) == 3
    wide = [Cell(0, 0, 100, 150), Cell(101, 0, 141, 150), Cell(142, 0, 242, 150)]   # 40 px > 32
    assert len(merge_slivers(wide, 32, 1.5)) == 3


def test_glass_doors_meeting_at_fused_handles_give_two_doors() -> None:
    """Two 0.36 m glass doors at 4 mm (180 x 150 px): the seam at column 90, each pane's frame edge a dark
    line 14 px inside the door's edges (columns 76 and 104, and 14 and 166), the two bars beside the seam
    fused into one handle over columns 80-99. The cut may not run through the handle, so the guillotine cuts
    at the frame edges 76 (the first of the equal dips) and then 104 (27 px from the cell's edge, over
    cells.min_side = 25 px; 14 and 166 are closer to an edge): a 27 px = 10.8 cm sliver [77, 104). With the
    sliver rule the doors meet at its middle, (77 + 104) // 2 = 90, each with half of the handle. Off (and
    ``cells.bar_pairs`` off): three cells. With the bar-pair rule alone the seam itself is cut through the
    handle's middle third, at column 90 too."""
    img = np.ones((150, 180, 3), np.float32)
    img[:, 90] *= 0.75
    img[:, [14, 76, 104, 166]] *= 0.8
    o = flat_ortho(img)
    cov = np.ones((150, 180), bool)
    fused = _bar(80, 100, 20, 82)
    on = sorted(split_cells(o, cov, [fused], HeuristicConfig()), key=lambda c: c.c0)
    assert [(c.c0, c.c1) for c in on] == [(0, 90), (91, 180)]
    assert [h.box for h in on[0].handles] == [(80, 20, 90, 82)] and [h.box for h in on[1].handles] == [(91, 20, 100, 82)]
    off = split_cells(o, cov, [fused], HeuristicConfig(cells={"sliver_max": 0.0, "bar_pairs": False}))
    assert [(c.c0, c.c1) for c in sorted(off, key=lambda c: c.c0)] == [(0, 76), (77, 104), (105, 180)]
    pairs = sorted(split_cells(o, cov, [fused], HeuristicConfig(cells={"sliver_max": 0.0})), key=lambda c: c.c0)
    assert [(c.c0, c.c1) for c in pairs] == [(0, 90), (91, 180)]


def test_a_bar_across_anothers_columns_is_not_beside_it() -> None:
    """A door's vertical bar (columns 10-17, rows 40-79: centre 14, 60) and a horizontal rail read as a
    handle below it (columns 5-114, rows 100-107: centre 60, 104): 46 px apart across, 44 down, so they were
    split side by side, cutting the door beside its own bar. The bar's columns lie within the rail's: the
    cell stays whole."""
    g = np.ones((150, 120))
    cov = np.ones(g.shape, bool)
    ev = np.zeros(g.shape, bool)
    bar, rail = _bar(10, 18, 40, 80), Handle((5, 100, 115, 108), True, np.zeros((0, 2), int))
    out = _split_handles(Cell(0, 0, 120, 150, [bar, rail]), ev, ev, cov, 25, (g, g), SeamConfig())
    assert len(out) == 1 and out[0].handles == [bar, rail]
