"""A glass cabinet's inside, seen through its doors (side walls, partitions, a shelf's lip as a handle), is no
front: hand-placed fronts behind a hand-made pane."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.perception.heuristic.behind_glass import (PaneRegion, front_samples, seen_through_glass,
                                                            share_behind_panes)
from react3d_core.perception.heuristic.fronts import Front
from tests.perception.heuristic.flat_orthos import flat_ortho


def _pane_region(grow: float) -> PaneRegion:
    """The plane y = 0 facing -y (the views at y < 0), x 0-1 m, z 0-1 m at 1 cm; one pane over x 0.30-0.70,
    z 0.20-0.80 (grid rows 20-79: z = 1 - row x 0.01)."""
    o = flat_ortho(np.ones((100, 100, 3), np.float32), res=0.01)
    panes = np.zeros((100, 100), bool)
    panes[20:80, 30:70] = True
    return PaneRegion.of(o, panes, grow)


def _front(center: tuple[float, float, float], n_out: tuple[float, float, float], u: tuple[float, float, float],
           w: float, h: float) -> Front:
    c, uu = np.array(center, float), np.array(u, float)
    cu = float(c @ uu)
    return Front(facet=-1, faces=np.zeros(0, np.int64), handle_facets=[], center=c, n_out=np.array(n_out, float), u=uu,
                 extent_u=(cu - w / 2, cu + w / 2), extent_v=(c[2] - h / 2, c[2] + h / 2))


def test_samples_cover_the_rectangle_by_hand() -> None:
    """A 0.5 x 0.5 m front centred at (1, 2, 0.5) with u = x: 5 x 5 points at x 0.8, 0.9, 1.0, 1.1, 1.2 and
    z 0.3 ... 0.7 (half a step, 0.05 m, in from each edge), all at y = 2."""
    pts = front_samples(_front((1.0, 2.0, 0.5), (0, -1, 0), (1, 0, 0), 0.5, 0.5))
    assert pts.shape == (25, 3)
    assert np.allclose(np.unique(pts[:, 0].round(6)), [0.8, 0.9, 1.0, 1.1, 1.2])
    assert np.allclose(np.unique(pts[:, 2].round(6)), [0.3, 0.4, 0.5, 0.6, 0.7]) and np.allclose(pts[:, 1], 2.0)


def test_share_behind_by_hand() -> None:
    """Points 0.2 m behind the plane (y = 0.2): x = 0.5 (in the pane), 0.25 (5 cm beside it), 0.1 (20 cm
    beside it), and one 0.2 m in front (y = -0.2) at x 0.5; all at z 0.5. Without growth 1 of 4 counts; grown
    by 0.09 m the point 5 cm off counts too: 2 of 4. The point in front never counts."""
    pts = np.array([[0.5, 0.2, 0.5], [0.25, 0.2, 0.5], [0.1, 0.2, 0.5], [0.5, -0.2, 0.5]])
    assert share_behind_panes(pts, _pane_region(0.0), 0.03, 0.8) == pytest.approx(0.25)
    assert share_behind_panes(pts, _pane_region(0.09), 0.03, 0.8) == pytest.approx(0.5)
    assert share_behind_panes(pts, _pane_region(0.09), 0.03, 0.1) == 0.0  # deeper than a cabinet: kept


def test_a_partition_behind_the_glass_goes_the_door_and_the_room_stay() -> None:
    """A partition (normal +x) at x = 0.32, 0.05-0.45 m behind the pane plane, z 0.3-0.7: its foot on the pane
    plane is x 0.32, inside the pane: seen through the glass. The glass door itself (on the plane), a front
    0.5 m in front of it (the room), a lid (normal up) behind the pane and a front behind the plane but beside
    the pane (x 0.9) stay."""
    partition = _front((0.32, 0.25, 0.5), (1, 0, 0), (0, 1, 0), 0.4, 0.4)
    door = _front((0.5, 0.0, 0.5), (0, -1, 0), (1, 0, 0), 0.5, 0.7)
    room = _front((0.5, -0.5, 0.5), (0, -1, 0), (1, 0, 0), 0.4, 0.4)
    lid = _front((0.5, 0.3, 0.5), (0, 0, 1), (1, 0, 0), 0.3, 0.3)
    beside = _front((0.9, 0.25, 0.5), (-1, 0, 0), (0, 1, 0), 0.4, 0.4)
    flags = seen_through_glass([partition, door, room, lid, beside], [_pane_region(0.09)], 0.03, 0.8, 0.5)
    assert flags == [True, False, False, False, False]
    assert seen_through_glass([partition], [], 0.03, 0.8, 0.5) == [False]
