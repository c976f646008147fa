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
