"""Handle-less image cells stacked in a column of one width (a drawer pedestal, a chest with edge pulls)
are fronts; a pair of cells, or a column whose widths differ, is not such a stack."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import FrontRulesConfig
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.image_fronts import stacks

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
