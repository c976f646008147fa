"""Per-view colour registration: its small formulas, hand-computed (the end-to-end recovery of known
per-view offsets is in test_image_fronts.py)."""

from __future__ import annotations

import numpy as np

from react3d_core.perception.heuristic.colour_sampling import ColourCalibration
from react3d_core.perception.heuristic.orthophoto import _edge_distance
from react3d_core.perception.heuristic.view_registration import _huber, _less_plane_means, _recentred


def test_recentred_removes_the_median_drift_only() -> None:
    calib = ColourCalibration(scale=0.9, dx=-4.0, dy=2.0)
    cur = {0: ColourCalibration(0.95, -4.0, 2.0), 1: ColourCalibration(1.0, 6.0, 3.0), 2: ColourCalibration(0.8, 96.0, 7.0)}
    out = _recentred(cur, calib)
    # medians: scale 0.95, dx 6, dy 3 -> drift (0.05, 10, 1); the far-off view does not move the others
    assert [round(out[k].scale, 6) for k in range(3)] == [0.9, 0.95, 0.75]
    assert [out[k].dx for k in range(3)] == [-14.0, -4.0, 86.0]
    assert [out[k].dy for k in range(3)] == [1.0, 2.0, 6.0]


def test_huber_cost_and_weights_hand_computed() -> None:
    e = np.array([0.0, 1.0, -2.0, 4.0])
    cost, w = _huber(e, 1.0)  # k = 1.345: quadratic for |e| <= k, linear beyond
    k = 1.345
    want = np.mean([0.0, 0.5, k * (2 - k / 2), k * (4 - k / 2)])
    assert abs(cost - want) < 1e-12
    np.testing.assert_allclose(w, [1.0, 1.0, k / 2, k / 4])


def test_less_plane_means_hand_computed() -> None:
    val = np.array([1.0, 3.0, np.nan, 10.0, 20.0], np.float32)
    plane = np.array([0, 0, 0, 2, 2])
    out = _less_plane_means(val, plane)
    np.testing.assert_allclose(out[[0, 1, 3, 4]], [-1.0, 1.0, -5.0, 5.0])
    assert np.isnan(out[2])


def test_edge_distance_hand_computed() -> None:
    depth = np.full((5, 9), 2.0, np.float32)
    depth[:, 6:] = 3.0  # a 1 m jump between columns 5 and 6: both are edge pixels (3x3 max - min)
    d = _edge_distance(depth, jump=0.05)
    np.testing.assert_allclose(d[2, [5, 6]], 0.0)
    assert d[2, 3] == 2.0 and d[2, 0] == 5.0 and d[2, 8] == 2.0  # exact Euclidean distance
    flat = _edge_distance(np.full((4, 6), 2.0, np.float32), jump=0.05)
    assert np.all(flat == 6.0)  # no jump anywhere: capped at the image's size
