"""The orthophoto's sampling shortcuts: a view is projected only in the grid window it can see, the
colour calibration samples only seen points (bincount variance), and both give what the plain
computation gives."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from react3d_core.camera import look_at
from react3d_core.config.heuristic import CalibrationConfig
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.perception.heuristic.orthophoto import (ColourCalibration, _disagreement, _Points, _remap_points,
                                                          _View, _window_in_view)


def test_remap_points_matches_remap_on_a_grid_beyond_remaps_side_limit() -> None:
    rng = np.random.default_rng(0)
    img = rng.uniform(0, 255, (120, 160)).astype(np.float32)
    n = 40_000  # over cv2.remap's 32767-per-side limit if laid out as one row
    x = rng.uniform(0, 159, n).astype(np.float32)
    y = rng.uniform(0, 119, n).astype(np.float32)
    want = cv2.remap(img, x.reshape(200, 200), y.reshape(200, 200), cv2.INTER_LINEAR,
                     borderMode=cv2.BORDER_CONSTANT, borderValue=0).reshape(-1)
    np.testing.assert_array_equal(_remap_points(img, x, y), want)


def test_window_holds_every_grid_point_inside_the_image() -> None:
    # a 3 m x 2 m wall at y = 0, 4 mm grid; a camera 1.2 m away sees only part of it
    u, v = np.meshgrid(np.arange(-1.5, 1.5, 0.004), np.arange(2.0, 0.0, -0.004))
    pts = np.stack([u, np.zeros_like(u), v], -1).astype(np.float32)
    K = np.array([[300.0, 0, 160], [0, 300.0, 120], [0, 0, 1]])
    for eye, target in (([0.3, -1.2, 1.0], [0.5, 0.0, 0.9]), ([-1.0, -0.8, 1.4], [-1.6, 0.0, 0.5])):
        w2c = np.linalg.inv(look_at(np.array(eye), np.array(target))).astype(np.float32)
        pc = pts @ w2c[:3, :3].T + w2c[:3, 3]
        x, y = K[0, 0] * pc[..., 0] / pc[..., 2] + K[0, 2], K[1, 1] * pc[..., 1] / pc[..., 2] + K[1, 2]
        inside = (pc[..., 2] > 0.1) & (x >= 0) & (x <= 319) & (y >= 0) & (y <= 239)
        r0, r1, c0, c1 = _window_in_view(pts, w2c, K, 320, 240)
        rows, cols = np.nonzero(inside)
        assert rows.min() >= r0 and rows.max() < r1 and cols.min() >= c0 and cols.max() < c1
        assert (r1 - r0) * (c1 - c0) < 0.6 * inside.size  # the window is a real saving here
        assert (r1 - r0) * (c1 - c0) < 1.3 * (np.ptp(rows) + 1) * (np.ptp(cols) + 1) + 4 * (r1 - r0 + c1 - c0)
    w2c_away = np.linalg.inv(look_at(np.array([0.0, -1.0, 1.0]), np.array([0.0, -3.0, 1.0]))).astype(np.float32)
    assert _window_in_view(pts, w2c_away, K, 320, 240) is None  # looking away from the wall


def test_view_crop_every_other_and_paste_keep_grid_positions() -> None:
    ok = np.zeros((9, 11), bool)
    ok[3:7, 4:10] = True
    xn = np.random.default_rng(1).normal(size=(9, 11, 2)).astype(np.float32)
    v = _View.cropped(0, xn[1:, 2:], ok[1:, 2:], 1, 2)  # a window starting at row 1, column 2
    assert (v.r0, v.c0, v.ok.shape) == (3, 4, (4, 6))
    np.testing.assert_array_equal(v.xn, xn[3:7, 4:10])
    full = v.paste(np.ones(v.ok.shape, np.float32), (9, 11))
    np.testing.assert_array_equal(np.isfinite(full), ok)
    half = v.every_other()  # grid pixels with even row and column indices: rows 4, 6 and columns 4, 6, 8
    assert (half.r0, half.c0) == (2, 2)
    np.testing.assert_array_equal(half.xn, xn[4:7:2, 4:10:2])


def test_disagreement_is_the_mean_per_pixel_variance_hand_computed() -> None:
    # 20 x 20 points seen by three views from the same pose, each point on a pixel centre
    K = np.array([[100.0, 0, 50], [0, 100.0, 50], [0, 0, 1]])
    intr = Intrinsics.from_K(K, 100, 100)
    frames = [Frame(frame_id=f"f{i}", rgb=ImageRef(path=Path(f"f{i}.png"), kind="png"), intrinsics=intr,
                    pose=np.eye(4)) for i in range(3)]
    px, py = np.meshgrid(np.arange(10, 30), np.arange(40, 60))
    xn = np.stack([(px.ravel() - 50) / 100.0, (py.ravel() - 50) / 100.0], 1).astype(np.float32)
    idx = np.arange(400)
    flat = np.full((100, 100), 100, np.float32)
    split = flat.copy()
    split[:, :20], split[:, 20:] = 50, 150  # the points' left half 50, right half 150: mean 100
    gray = {0: flat, 1: split, 2: flat}
    views = [_Points(i, idx, xn) for i in range(3)]
    # per point the normalised values are {1, 0.5, 1} or {1, 1.5, 1}: variance 1/18 either way
    assert abs(_disagreement(views, frames, gray, ColourCalibration(), 400, CalibrationConfig()) - 1 / 18) < 1e-6
    # points seen by fewer than 3 views do not count; fewer than 100 such points: no measure
    assert np.isnan(_disagreement(views[:2], frames, gray, ColourCalibration(), 400, CalibrationConfig()))
    # a focal scale that throws every point out of the image leaves nothing to compare
    assert np.isnan(_disagreement(views, frames, gray, ColourCalibration(scale=20.0), 400, CalibrationConfig()))


def _walk_frames() -> list[Frame]:
    """Six frames of a dense walk, 2 cm apart, 1.4-1.5 m in front of a wall at y = 0, all looking at
    (0, 0, 0.5); then one frame from each side, 1.4 m away at 34 degrees."""
    intr = Intrinsics.from_K(np.array([[300.0, 0, 320], [0, 300.0, 240], [0, 0, 1]]), 640, 480)
    eyes = [(0.0, -1.5 + 0.02 * k, 0.5) for k in range(6)] + [(-0.8, -1.2, 0.5), (0.8, -1.2, 0.5)]
    return [Frame(frame_id=f"f{i}", rgb=ImageRef(path=Path(f"f{i}.png"), kind="png"), intrinsics=intr,
                  pose=look_at(np.array(e), np.array([0.0, 0.0, 0.5]))) for i, e in enumerate(eyes)]


def test_views_are_picked_apart_not_from_one_stretch_of_the_walk() -> None:
    """A 2 m x 1 m wall, three views to fuse. Picked for spread: the nearest walk frame (sharpest: cosine
    over distance), then its neighbours within 15 cm and 10 degrees are passed over and the two side
    frames follow. Without ``pick_spread`` (the default) the three are all walk frames, alike and sharing
    one occluder."""
    from react3d_core.config.heuristic import OrthoConfig
    from react3d_core.perception.heuristic.orthophoto import _pick_views
    from react3d_core.perception.heuristic.planes import Plane

    u, v = np.meshgrid(np.arange(-1.0, 1.0, 0.01), np.arange(1.0, 0.0, -0.01))
    grid = np.stack([u, np.zeros_like(u), v], -1)
    plane = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.zeros(0, np.int64),
                  (-1.0, 1.0), (0.0, 1.0), 2.0)
    frames = _walk_frames()
    assert _pick_views([plane], frames, [grid], OrthoConfig(max_views=3, pick_spread=True)) == [{5, 6, 7}]
    assert _pick_views([plane], frames, [grid], OrthoConfig(max_views=3))[0] <= set(range(6))
    # with room for all, every frame the spread passed over stays out; without the cap on neighbours, all
    assert _pick_views([plane], frames, [grid], OrthoConfig(max_views=30, pick_spread=True)) == [{5, 6, 7}]
    assert _pick_views([plane], frames, [grid], OrthoConfig(max_views=30, pick_spread=True, pick_sep=0.0)) == [set(range(8))]
