"""Front-level development score (react3d_core.metrics.front_match), hand-computed."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.geometry import iou_matrix
from react3d_core.metrics.front_match import match_fronts

AREA = np.array([1.0, 1.0, 2.0, 2.0, 1.0, 3.0])


def test_area_iou_hand_computed() -> None:
    """GT A = faces {0, 1, 2} (area 4), B = {3, 4} (area 3). Prediction {0, 1} (area 2): IoU with A
    2 / 4 = 0.5. Prediction {2, 3, 4, 5} (area 8): with A 2 / (4 + 8 - 2) = 0.2, with B 3 / (3 + 8 - 3)
    = 0.375. Prediction {3, 4}: with B 1.0."""
    gt = [np.array([0, 1, 2]), np.array([3, 4])]
    pred = [np.array([0, 1]), np.array([2, 3, 4, 5]), np.array([3, 4])]
    iou = iou_matrix(gt, pred, AREA)
    assert iou == pytest.approx(np.array([[0.5, 0.2, 0.0], [0.0, 0.375, 1.0]]))
    s = match_fronts(gt, pred, AREA)
    assert s.pairs == ((0, 0, 0.5), (1, 2, 1.0))         # IoU 0.5 counts (>=); 0.375 does not
    assert (s.tp, s.n_pred, s.n_gt) == (2, 3, 2)
    assert s.precision == pytest.approx(2 / 3) and s.recall == 1.0 and s.f1 == pytest.approx(0.8)


def test_greedy_takes_the_better_prediction() -> None:
    """GT {0, 1, 2, 3} (area 6): prediction {0, 1, 2} has IoU 4 / 6, {0, 1, 2, 3, 4} 6 / 7; the part is
    matched once, to the second; the first is a false front (F1 = 2 x 1 / (2 + 1))."""
    s = match_fronts([np.array([0, 1, 2, 3])], [np.array([0, 1, 2]), np.array([0, 1, 2, 3, 4])], AREA)
    assert s.pairs == ((0, 1, pytest.approx(6 / 7)),)
    assert s.f1 == pytest.approx(2 / 3)


def test_empty_sides() -> None:
    """No predictions: recall and F1 0; nothing on either side: all 0, no division by zero."""
    s = match_fronts([np.array([0])], [], AREA)
    assert (s.tp, s.recall, s.f1, s.precision) == (0, 0.0, 0.0, 0.0)
    assert match_fronts([], [], AREA).f1 == 0.0


def test_bench_fronts_scores_a_scene(synthetic_scene, tmp_path) -> None:
    """The front-level benchmark on a clean procedural kitchen: one row, counts consistent with the
    scene's ground truth, the JSON written, and most fronts found (the heuristic's home ground)."""
    import json

    from benchmarks.bench_fronts import main
    from flows.bench.runner import _gt_dir
    from react3d_core.ground_truth.articulate3d import read_articulate3d

    root = synthetic_scene(seed=0, n_frames=12)
    out = tmp_path / "fronts.json"
    res = main(["--scenes", str(root), "--jobs", "1", "--json", str(out)])
    assert json.loads(out.read_text())["total"] == res["total"]
    (row,) = res["rows"]
    assert row["gt"] == len(read_articulate3d(_gt_dir(root)).movable)
    assert row["tp"] <= min(row["pred"], row["gt"])
    assert row["f1"] == pytest.approx(2 * row["tp"] / (row["pred"] + row["gt"]))
    assert row["f1"] >= 0.6
