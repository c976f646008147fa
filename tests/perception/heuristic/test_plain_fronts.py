"""Which handle-less image cells are kept as fronts: the end of a row or the top of a stack cut on one side
only (its other sides are the plane's outline), the fronts of a piece standing free, and tall fronts with a
horizontal bar typed as side-hinged doors."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import CellConfig, FrontRulesConfig, HeuristicConfig
from react3d_core.perception.heuristic.front_cells import Cell, split_cells
from react3d_core.perception.heuristic.fronts import Front, _joint
from react3d_core.perception.heuristic.image_fronts import (fronts_share, is_tiled, piece_front, piece_of_fronts, plain_fronts_kept,
                                                           seen_share, stacks)
from tests.perception.heuristic.flat_orthos import flat_ortho

N = np.array([0.0, -1.0, 0.0])      # facing -y; u = z x n = (1, 0, 0)
U = np.array([1.0, 0.0, 0.0])


def _front(u0: float, u1: float, v0: float, v1: float, handle: bool = False) -> Front:
    c = np.array([0.5 * (u0 + u1), 0.0, 0.5 * (v0 + v1)])
    f = Front(facet=-1, handle_facets=[], center=c, n_out=N.copy(), u=U.copy(), extent_u=(u0, u1), extent_v=(v0, v1))
    if handle:
        f.handle_points = np.array([[0.5 * (u0 + u1) - 0.1, 0.0, v1 - 0.05], [0.5 * (u0 + u1) + 0.1, 0.0, v1 - 0.05]])
    return f


def test_a_row_end_cut_on_one_side_is_kept_beside_a_seamed_front() -> None:
    """A sideboard's three doors 0.5 m wide: the middle one cut out by straight seams on both sides
    (``gridded``), the two at the ends cut on one side only, their outer sides the plane's outline. Both
    ends are kept beside the middle one; a lone single-cut cell (a wall panel) is not; with no seamed
    neighbour (the middle one not gridded) nothing is kept."""
    r = FrontRulesConfig()
    left, mid, right = _front(0.0, 0.5, 0.1, 0.8), _front(0.51, 1.01, 0.1, 0.8), _front(1.02, 1.52, 0.1, 0.8)
    lone = _front(3.0, 3.6, 0.1, 1.0)
    fronts = [left, mid, right, lone]
    singles = {id(left), id(right), id(lone)}
    assert plain_fronts_kept(fronts, r, {id(mid)}, set(), singles, set()) == [left, mid, right]
    assert plain_fronts_kept(fronts, r, set(), set(), singles, set()) == []


def test_a_single_cut_cell_beside_only_a_single_cut_cell_is_not_kept() -> None:
    """Two single-cut cells side by side (one seam across a plain panel): neither is kept by the other."""
    a, b = _front(0.0, 0.5, 0.1, 0.8), _front(0.51, 1.01, 0.1, 0.8)
    assert plain_fronts_kept([a, b], FrontRulesConfig(), set(), set(), {id(a), id(b)}, set()) == []


def test_a_pedestal_top_drawer_cut_on_one_side_completes_the_stack() -> None:
    """A desk pedestal of three drawers: the top one is cut on its bottom side only (its top is the
    plane's outline, under the desk top). With it the column holds three cells and is a stack; without it
    (single-cut cells left out) two cells are no stack and no drawer is kept."""
    r = FrontRulesConfig()
    low, mid, top = _front(0.0, 0.42, 0.02, 0.2), _front(0.0, 0.42, 0.21, 0.39), _front(0.0, 0.42, 0.4, 0.57)
    col = [low, mid, top]
    stacked = stacks(col, r, 3)
    assert stacked == {id(f) for f in col}
    assert plain_fronts_kept(col, r, set(), stacked, {id(top)}, set()) == col
    assert plain_fronts_kept([low, mid], r, set(), stacks([low, mid], r, 3), set(), set()) == []


def test_a_handled_neighbour_keeps_a_row_end_and_pieces_are_kept() -> None:
    """A dishwasher (handle-less, single-cut) beside a door with a handle is kept; the two doors of a
    handle-less fridge (``pieces``) are kept whatever their cuts."""
    r = FrontRulesConfig()
    door, dw = _front(0.0, 0.6, 0.1, 0.8, handle=True), _front(0.61, 1.21, 0.1, 0.8)
    assert plain_fronts_kept([door, dw], r, set(), set(), {id(dw)}, set()) == [door, dw]
    top, low = _front(3.0, 3.66, 0.7, 1.88), _front(3.0, 3.66, 0.04, 0.69)
    assert plain_fronts_kept([top, low], r, set(), set(), {id(top), id(low)}, {id(top), id(low)}) == [top, low]


def test_piece_front_is_a_small_filled_rectangle() -> None:
    """At 1 cm per px: a fridge front 0.66 x 1.84 m, fully covered, is a piece; a 3 m wide wall is not
    (``piece_max_w`` 2 m); a 1.5 m plane with a 0.6 m kneehole cut out of its lower 0.6 m (fill 0.67) is a
    piece at fill 0.6 but not at 0.7; a 1.5 m stretch of wall seen between furniture (fill 0.3) is not; a
    plane taller than ``max_h`` is not; ``max_w`` 0 turns the rule off."""
    fridge = np.zeros((200, 100), bool)
    fridge[10:194, 20:86] = True
    assert piece_front(fridge, 0.01, 2.0, 2.3, 0.6)
    assert not piece_front(fridge, 0.01, 0.0, 2.3, 0.6)
    wall = np.ones((170, 300), bool)
    assert not piece_front(wall, 0.01, 2.0, 2.3, 0.6)
    desk = np.ones((72, 150), bool)
    desk[12:, 45:105] = False
    assert desk.mean() == (72 * 150 - 60 * 60) / (72 * 150)  # 0.667
    assert piece_front(desk, 0.01, 2.0, 2.3, 0.6)
    assert not piece_front(desk, 0.01, 2.0, 2.3, 0.7)
    behind = np.zeros((170, 150), bool)
    behind[:, :20] = True
    behind[:, 130:] = True
    behind[:5, :] = True                                     # two strips joined along the top: fill 0.29
    assert not piece_front(behind, 0.01, 2.0, 2.3, 0.6)
    tall = np.ones((240, 80), bool)
    assert not piece_front(tall, 0.01, 2.0, 2.3, 0.6)
    assert not piece_front(np.zeros((10, 10), bool), 0.01, 2.0, 2.3, 0.6)


def test_a_control_strip_does_not_make_an_appliance_front_a_tiling() -> None:
    """At 1 cm per px, all covered: a dishwasher 0.45 m wide, its drop door 0.65 m tall below a 0.10 m control
    strip cut at its display into 0.20 m and 0.25 m cells: one cell (0.20 x 0.10) is tile-sized (< 0.25 m
    both ways), so the old any-cell test called the plane tiled and its handle-less door was no piece's
    front; with ``min_tiles`` 3 it is not tiled. A splash-back cut into 3 x 4 tiles of 0.15 m is tiled; an
    uncovered tile-sized cell (a hole) does not count."""
    cov = np.ones((75, 45), bool)
    dishwasher = [Cell(0, 0, 20, 10), Cell(20, 0, 45, 10), Cell(0, 10, 45, 75)]
    cc = CellConfig()
    assert cc.min_tiles == 3
    assert not is_tiled(dishwasher, cov, 0.01, cc)
    assert is_tiled(dishwasher, cov, 0.01, CellConfig(min_tiles=1, tile_edge_strips=True))  # the rules before
    tiles = np.ones((45, 60), bool)
    splash = [Cell(c, r, c + 15, r + 15) for r in range(0, 45, 15) for c in range(0, 60, 15)]
    assert is_tiled(splash, tiles, 0.01, cc)
    holes = tiles.copy()
    holes[:, 15:] = False
    holes[30:, :] = False                                               # two tiles covered, ten holes
    assert not is_tiled(splash, holes, 0.01, cc)


def test_a_piece_is_made_of_its_fronts() -> None:
    """At 1 cm per px (u0 0, top at z 0.84 m): a washing machine 0.60 x 0.84 m whose porthole (a 0.40 m
    square here, rows 30-70, columns 10-50) is no plane. Covered: 5040 - 1600 = 3440 px. Its control strip
    cell u 0.20-0.60, z 0.62-0.84 covers 40 x 22 = 880 px: share 880 / 3440 = 0.256, below
    ``piece_front_share`` 0.5. A dishwasher's door u 0-0.60, z 0-0.74 on a full 0.60 x 0.84 m plane covers
    60 x 74 / (60 x 84) = 0.881. A front reaching past the grid is clipped to it."""
    cov = np.ones((84, 60), bool)
    cov[30:70, 10:50] = False
    o = flat_ortho(np.ones((84, 60, 3)), 0.01)
    strip = _front(0.20, 0.60, 0.62, 0.84)
    assert abs(fronts_share([strip], o, cov) - 880 / 3440) < 1e-9
    assert fronts_share([strip], o, cov) < CellConfig().piece_front_share
    full = np.ones((84, 60), bool)
    door = _front(0.0, 0.60, 0.0, 0.74)
    assert abs(fronts_share([door], o, full) - 74 / 84) < 1e-9
    assert abs(fronts_share([_front(-0.5, 0.60, -0.2, 2.0)], o, full) - 1.0) < 1e-9
    assert fronts_share([], o, full) == 0.0
    assert fronts_share([door], o, np.zeros((84, 60), bool)) == 0.0


def test_a_tall_front_with_a_horizontal_bar_is_a_side_hinged_door() -> None:
    """A wardrobe door 0.5 x 1.86 m (bottom at 0.05 m) with a 0.2 m horizontal bar 0.3 m above its
    middle: high on a tall front read as a bottom-hinged drop door; no such door is 1.86 m tall
    (``flap_max_h`` 1.2 m), so it is hinged at a side (vertical axis). A 0.6 m oven door with the same bar
    stays a drop door; with ``flap_max_h`` 2 m the wardrobe door is a drop door as before the rule."""
    bar = lambda u, v: np.array([[u - 0.1, 0.0, v], [u + 0.1, 0.0, v], [u, 0.0, v + 0.01]])  # noqa: E731
    tall = _front(0.0, 0.5, 0.05, 1.91)
    kind, art = _joint(tall, bar(0.25, 1.28), [], FrontRulesConfig())
    assert kind == "door" and abs(art.axis[2]) == 1.0
    assert _joint(tall, bar(0.25, 1.28), [], FrontRulesConfig(flap_max_h=2.0))[0] == "drop"
    oven = _front(0.0, 0.6, 0.2, 0.8)
    kind, art = _joint(oven, bar(0.3, 0.72), [], FrontRulesConfig())
    assert kind == "drop" and abs(art.axis[0]) == 1.0


_ortho = flat_ortho


def test_bright_rows_cut_a_handle_less_chest_into_its_drawers() -> None:
    """A handle-less chest front 0.6 x 0.42 m at 4 mm (150 x 105 px, grey 0.5 with noise) whose three
    drawers are parted by 2 px rows brighter than the front (0.75: the lit top edge of the drawer below,
    as a rendered TSDF chest shows them). No row is darker than its neighbours, so without ``seams.ridges``
    the front stays one cell; with it the bright rows cut it into three drawers 35 px tall. A bright
    vertical line is no seam (no light falls into a vertical gap): the cells stay 150 px wide."""
    rng = np.random.default_rng(5)
    img = 0.5 + rng.normal(0, 0.004, (105, 150, 3)).astype(np.float32)
    img[34:36] = 0.75
    img[69:71] = 0.75
    img[:, 74:76] = 0.75
    o = _ortho(img)
    cov = np.ones(img.shape[:2], bool)
    off = HeuristicConfig(seams={"ridges": False})
    assert len(split_cells(o, cov, [], off)) == 1
    cells = sorted(split_cells(o, cov, [], HeuristicConfig()), key=lambda c: c.r0)
    assert len(cells) == 3
    assert [c.c1 - c.c0 for c in cells] == [150, 150, 150]
    assert [(c.r0, c.r1) for c in cells] == [(0, 34), (35, 69), (70, 105)]  # cut on the bright rows 34, 69


def test_a_piece_is_what_the_views_see() -> None:
    """At 1 cm per px: a 0.60 x 0.84 m panel, all of it in the scan, cut by one row at z 0.60 into a 0.60 x 0.60 m
    handle-less "front" below (share 3600 / 5040 = 0.71 of the plane). Seen all over it is a piece's front. A
    sideboard's side behind a chair: the views see only the top 24 rows (1440 / 5040 = 0.286 of it) and the
    same cut (the chair's edge) -- no piece with ``piece_seen`` 0.8 (the default); with 0 (off) it is one."""
    cov = np.ones((84, 60), bool)
    front = [_front(0.0, 0.60, 0.0, 0.60)]
    seen = flat_ortho(np.ones((84, 60, 3)), 0.01)
    assert seen_share(seen, cov) == 1.0
    assert piece_of_fronts(front, seen, cov, HeuristicConfig())
    hidden = flat_ortho(np.ones((84, 60, 3)), 0.01)
    hidden.n_views[24:, :] = 0
    assert abs(seen_share(hidden, cov) - 1440 / 5040) < 1e-9
    assert not piece_of_fronts(front, hidden, cov, HeuristicConfig())
    assert piece_of_fronts(front, hidden, cov, HeuristicConfig(cells={"piece_seen": 0.0}))
    assert seen_share(hidden, np.zeros((84, 60), bool)) == 0.0
