"""Handle-less image cells stacked in a column of one width (a drawer pedestal, a chest with edge pulls)
are fronts; a pair of cells, or a column whose widths differ, is not such a stack."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import FrontRulesConfig
from react3d_core.perception.heuristic.front_cells import Handle
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.image_fronts import stacks
from react3d_core.perception.heuristic.orthophoto import Orthophoto

N = np.array([0.0, -1.0, 0.0])      # facing -y; u = z x n = (1, 0, 0)
U = np.array([1.0, 0.0, 0.0])


def _front(u0: float, u1: float, v0: float, v1: float, depth: float = 0.0) -> Front:
    c = np.array([0.5 * (u0 + u1), -depth, 0.5 * (v0 + v1)])
    return Front(facet=-1, handle_facets=[], center=c, n_out=N.copy(), u=U.copy(), extent_u=(u0, u1), extent_v=(v0, v1))


def test_three_drawers_one_on_another_are_a_stack() -> None:
    col = [_front(0.0, 0.42, 0.05, 0.22), _front(0.0, 0.42, 0.23, 0.40), _front(0.01, 0.42, 0.41, 0.58)]
    other = _front(1.0, 1.4, 0.05, 0.6)                       # a lone door beside them
    got = stacks(col + [other], FrontRulesConfig(), 3)
    assert got == {id(f) for f in col}
    assert stacks(col + [other], FrontRulesConfig(), 4) == set()
    assert stacks(col + [other], FrontRulesConfig(), 0) == set()


def test_pairs_gaps_other_widths_and_other_planes_are_no_stack() -> None:
    r = FrontRulesConfig()                                  # neighbour_align 5 cm, neighbour_gap 3 cm
    assert stacks([_front(0.0, 0.42, 0.05, 0.22), _front(0.0, 0.42, 0.23, 0.40)], r, 3) == set()
    narrower = [_front(0.0, 0.42, 0.05, 0.22), _front(0.0, 0.30, 0.23, 0.40), _front(0.0, 0.42, 0.41, 0.58)]
    assert stacks(narrower, r, 3) == set()                  # the middle cell is 12 cm narrower
    gap = [_front(0.0, 0.42, 0.05, 0.22), _front(0.0, 0.42, 0.23, 0.40), _front(0.0, 0.42, 0.44, 0.60)]
    assert stacks(gap, r, 3) == set()                       # 4 cm between the top two
    behind = [_front(0.0, 0.42, 0.05, 0.22), _front(0.0, 0.42, 0.23, 0.40, depth=0.05),
              _front(0.0, 0.42, 0.41, 0.58)]
    assert stacks(behind, r, 3) == set()                    # the middle one 5 cm behind the others' plane


def test_a_seam_an_edge_pull_hangs_from_is_cut() -> None:
    """A 0.7 x 0.72 m chest front (175 x 180 px at 4 mm) of three 60 px drawers, 2 px seams at rows 59 and
    119, each drawer's edge pull a dark lip 5 px tall along its top edge, 60 % of its width (columns 35-139).
    The top drawer's lip lies on the plane's outline (rows 0-4) and is no handle (handles.outline_margin),
    so each seam has a handle just below it and none above.

    - As found before: the lips' own edges were the strongest lines (colour steps), and a horizontal cut
      must leave a handle on both sides, so the one cut fell along the first lip's lower edge: the top
      drawer and most of the second were one cell.
    - With seams read past the handles (``cells.seams_past_handles``) the seams are the only lines, but
      a cut along the first must leave a handle above: the strip over it is cut off as a cell's edge
      strip, or nothing is cut; no cell ends within 3 px of row 60.
    - With ``cells.edge_pull`` as well, the cuts run along both seams: three cells."""
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic.front_cells import find_handles, split_cells
    from tests.perception.heuristic.flat_orthos import flat_ortho

    rng = np.random.default_rng(5)
    img = np.full((180, 175, 3), 0.6, np.float32) + rng.normal(0, 0.003, (180, 175, 3)).astype(np.float32)
    for r in (59, 119):
        img[r:r + 2] = 0.45
    for r in (0, 61, 121):
        img[r:r + 5, 35:140] = 0.15
    o, cov = flat_ortho(img), np.ones(img.shape[:2], bool)
    got = {}
    for key, cells in (("before", {"seams_past_handles": False, "edge_pull": 0.0}), ("past", {"edge_pull": 0.0}),
                       ("both", {})):
        cfg = HeuristicConfig(cells=cells)
        hs = find_handles(o, cov, cfg)
        assert sorted(h.box[1] for h in hs) == [62, 122] and all(h.horizontal for h in hs)
        got[key] = sorted((c.r0, c.r1) for c in split_cells(o, cov, hs, cfg))
    assert len(got["before"]) == 2 and 64 <= got["before"][0][1] <= 67
    assert not any(abs(r1 - 60) <= 3 for _, r1 in got["past"])
    assert len(got["both"]) == 3
    assert all(abs(a[1] - b) <= 2 for a, b in zip(got["both"], (60, 120)))


def test_fill_along_by_hand() -> None:
    """A 3 x 5 image, rows [0..4] + 10 * row, the middle three pixels of row 1 masked. Along rows they are
    blended from 10 and 14 (11, 12, 13: here the row's own values, as it is linear); along columns from
    rows 0 and 2 (the mean of 1 and 21, 2 and 22, 3 and 23: 11, 12, 13 as well). A masked run at the row's
    end takes the one value beside it; a NaN neighbour is passed over to the next finite value (and stays
    NaN itself); colour channels ride along."""
    from react3d_core.perception.heuristic.front_cells import fill_along

    g = np.arange(5)[None, :] + 10.0 * np.arange(3)[:, None]
    m = np.zeros((3, 5), bool)
    m[1, 1:4] = True
    g_bad = np.where(m, -99.0, g)
    assert np.allclose(fill_along(g_bad, m, 1), g) and np.allclose(fill_along(g_bad, m, 0), g)
    end = np.zeros((3, 5), bool)
    end[1, 3:] = True
    assert np.allclose(fill_along(g_bad * 0 + g, end, 1)[1, 3:], [12.0, 12.0])
    h = g.copy()
    h[1, 0] = np.nan
    assert np.allclose(fill_along(h, m, 1)[1, 1:4], [14.0, 14.0, 14.0]) and np.isnan(fill_along(h, m, 1)[1, 0])
    h[1, 4] = np.nan
    assert np.isnan(fill_along(h, m, 1)[1]).all()
    w = np.arange(7)[None, :] + np.zeros((2, 7))
    w[0, 1] = np.nan
    mw = np.zeros((2, 7), bool)
    mw[0, 2:5] = True
    assert np.allclose(fill_along(w, mw, 1)[0, 2:5], [2.0, 3.0, 4.0])  # blended from col 0 (0) and col 5 (5)
    rgb = np.stack([g_bad, 2 * g_bad, 3 * g_bad], -1)
    assert np.allclose(fill_along(rgb, m, 1)[1, 1:4], np.array([[11, 22, 33], [12, 24, 36], [13, 26, 39]]))


def test_a_faint_seam_over_an_edge_pull_is_cut() -> None:
    """The chest of the test above with faint seams (2 px rows 0.012 darker than the 0.6 front: 12 noise
    units, under ``seams.dip_z`` = 15, so no straight cut by itself, as a white TSDF front's seams). The
    lips vouch for the seams right over them (``_split_at_pulls``, at least ``seams.between_z`` = 3 units):
    three cells with ``cells.edge_pull``, cut within 2 px of rows 60 and 120; without it the seams under
    the first lip's top are never cut there."""
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic.front_cells import find_handles, split_cells
    from tests.perception.heuristic.flat_orthos import flat_ortho

    rng = np.random.default_rng(5)
    img = np.full((180, 175, 3), 0.6, np.float32) + rng.normal(0, 0.003, (180, 175, 3)).astype(np.float32)
    for r in (59, 119):
        img[r:r + 2] -= 0.012
    for r in (0, 61, 121):
        img[r:r + 5, 35:140] = 0.15
    o, cov = flat_ortho(img), np.ones(img.shape[:2], bool)
    got = {}
    for pull in (0.0, 0.012):
        cfg = HeuristicConfig(cells={"edge_pull": pull})
        hs = find_handles(o, cov, cfg)
        assert sorted(h.box[1] for h in hs) == [61, 121]
        got[pull] = sorted((c.r0, c.r1) for c in split_cells(o, cov, hs, cfg))
    assert not any(abs(r1 - 60) <= 3 for _, r1 in got[0.0])
    assert len(got[0.012]) == 3 and all(abs(a[1] - b) <= 2 for a, b in zip(got[0.012], (60, 120)))


def _door_pair_with_groove() -> tuple[Orthophoto, np.ndarray, Handle]:
    """A 0.8 x 0.64 m door pair (200 x 160 px at 4 mm) as a 1 cm TSDF scan shows it: the seam where the doors
    meet is a groove 7 px wide (columns 97-103) the surface leaves along the whole height, unseen and
    uncovered; the doors' bars either side of it (columns 88-96 and 104-112, rows 20-80) fused into one blob
    across it, a handle 25 px wide. Nothing else on the doors makes a line."""
    from tests.perception.heuristic.flat_orthos import flat_ortho

    rng = np.random.default_rng(7)
    img = np.full((160, 200, 3), 0.7, np.float32) + rng.normal(0, 0.003, (160, 200, 3)).astype(np.float32)
    img[20:80, 88:97] = img[20:80, 104:113] = 0.2
    o = flat_ortho(img)
    cov = np.ones(img.shape[:2], bool)
    cov[:, 97:104] = False
    o.n_views[~cov] = 0
    rows, cols = np.mgrid[20:80, 88:113]
    return o, cov, Handle((88, 20, 113, 80), False, np.stack([cols.ravel(), rows.ravel()], 1))


def test_a_door_pair_is_cut_along_its_groove_through_its_fused_bars() -> None:
    """Without the groove rule (``cells.groove_share`` 0) the seam shows no dark line to cut at (it is unseen),
    and without the bar-pair rule (``cells.bar_pairs``) the one handle blocks every column it covers: one
    cell either way. With both, the cut runs along the groove's middle (column 100) and each door holds its
    own bar: the handle's pixels either side of the cut."""
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic.front_cells import split_cells

    o, cov, bar = _door_pair_with_groove()
    for cells in ({"groove_share": 0.0}, {"bar_pairs": False}):
        assert len(split_cells(o, cov, [bar], HeuristicConfig(cells=cells))) == 1
    left, right = sorted(split_cells(o, cov, [bar], HeuristicConfig()), key=lambda c: c.c0)
    assert left.c1 == 100 and right.c0 == 101
    ((a,), (b,)) = left.handles, right.handles
    assert a.box == (88, 20, 100, 80) and b.box == (101, 20, 113, 80)


def test_groove_cut_hand_computed() -> None:
    """Line coverage (a 40-line cell, 30 px along each line, one piece): 30 everywhere but a band. The cell's
    median line coverage is 30; under 0.3 x 30 = 9 is a groove line. Lines 18-21 at 5 px: a 4-line groove,
    cut at its middle, line 19; ten lines covered on each side. A band at 10 px (over 9) is none; a band
    wider than groove_px is none, and so is one whose middle is blocked (a handle). A band uncovered in its
    first 25 px only (5 px covered per line: low over the whole line) is a groove judged as one piece, but
    none judged in pieces of 10 px (``piece_sides`` 1): in the last piece it is covered 5 of 10, over
    0.3 x 10. A cell whose median line is covered under ``groove_cover`` of its length is patchy: none."""
    from react3d_core.config.heuristic import CellConfig
    from react3d_core.perception.heuristic.front_cells import _groove_cut

    q = CellConfig(groove_share=0.3, groove_px=5)
    free = np.zeros(40, bool)

    def cov_with(band: slice, per_line: int) -> np.ndarray:
        cov = np.ones((30, 40), bool)
        cov[per_line:, band] = False
        return cov

    assert _groove_cut(cov_with(slice(18, 22), 5), 0, 10, q, free, 3) == (19, 1.0)
    assert _groove_cut(cov_with(slice(18, 22), 10), 0, 10, q, free, 3) == (-1, 0.0)
    assert _groove_cut(cov_with(slice(16, 22), 5), 0, 10, q, free, 3) == (-1, 0.0)
    blocked = free.copy()
    blocked[19] = True
    assert _groove_cut(cov_with(slice(18, 22), 5), 0, 10, q, blocked, 3) == (-1, 0.0)
    patchy = cov_with(slice(18, 22), 5)
    patchy[::2] = False                                       # every line covered 15 of 30: under 0.7 x 30
    assert _groove_cut(patchy, 0, 10, q, free, 3) == (-1, 0.0)
    assert _groove_cut(patchy, 0, 10, CellConfig(groove_share=0.3, groove_px=5, groove_cover=0.5), free, 3) == (19, 1.0)
    half = np.ones((30, 40), bool)
    half[:25, 18:22] = False
    assert _groove_cut(half, 0, 10, q, free, 3) == (19, 1.0)
    assert _groove_cut(half, 0, 10, q, free, 1) == (-1, 0.0)


def _bar(c0: int, r0: int, c1: int, r1: int) -> Handle:
    rows, cols = np.mgrid[r0:r1, c0:c1]
    return Handle((c0, r0, c1, r1), True, np.stack([cols.ravel(), rows.ravel()], 1))


def test_a_stack_of_edge_pulls_is_cut_on_its_pitch() -> None:
    """A 0.6 x 0.59 m white chest (150 x 148 px at 4 mm) of four 37 px drawers with no visible seam, each
    drawer's edge pull 9 px tall just under its top edge (rows 36, 73, 110; the top drawer's lies on the
    outline and is not found). Three bars at a 37 px pitch in a cell 148 px = 4 pitches tall: cut at
    rows 37, 74 and 111, each bar in its own drawer, the top drawer handle-less. Without the rule
    (``cells.pitch_tol`` 0) the cuts fall halfway between the bars (row 59 between the first two), a
    drawer's half off. With a seam at row 60 the rule stands aside and the seam is cut."""
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic.front_cells import split_cells
    from tests.perception.heuristic.flat_orthos import flat_ortho

    rng = np.random.default_rng(11)
    img = np.full((148, 150, 3), 0.85, np.float32) + rng.normal(0, 0.003, (148, 150, 3)).astype(np.float32)
    bars = [_bar(30, r, 120, r + 9) for r in (36, 73, 110)]
    for b in bars:
        img[b.box[1]:b.box[3], b.box[0]:b.box[2]] = 0.3
    o, cov = flat_ortho(img), np.ones(img.shape[:2], bool)
    cells = sorted(split_cells(o, cov, bars, HeuristicConfig()), key=lambda c: c.r0)
    assert [(c.r0, c.r1) for c in cells] == [(0, 37), (38, 74), (75, 111), (112, 148)]
    assert [len(c.handles) for c in cells] == [0, 1, 1, 1]
    off = sorted(split_cells(o, cov, bars, HeuristicConfig(cells={"pitch_tol": 0.0})), key=lambda c: c.r0)
    assert off[0].r1 == 59
    seam = img.copy()
    seam[60:62] = 0.7
    cut = sorted(split_cells(flat_ortho(seam), cov, bars, HeuristicConfig()), key=lambda c: c.r0)
    assert abs(cut[0].r1 - 60) <= 1
