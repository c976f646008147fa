"""Hand-computed detection / articulation / MOD cases on tiny vertex sets."""

import numpy as np
import pytest

from react3d_core.config.metrics import EvaluationConfig
from react3d_core.data.parts import Articulation
from react3d_core.metrics import evaluate_sets, iou_matrix, summarize, to_json_dict
from react3d_core.metrics.scene_metrics import aggregate

CFG = EvaluationConfig()
VERTS = np.array([[i, 0.0, 0.0] for i in range(100)], float)  # vertex i at x=i: diag of ids a..b = b-a

REV_Z = Articulation(joint_type="revolute", axis=[0, 0, 1], origin=[0, 0, 0])
PRI_X = Articulation(joint_type="prismatic", axis=[1, 0, 0], origin=[0, 0, 0])


def r(a, b):
    return np.arange(a, b)


def test_iou_matrix_hand_values():
    m = iou_matrix([r(0, 10), r(5, 15)], [r(0, 10), r(20, 30)])
    assert m[0, 0] == 1.0 and m[0, 1] == 0.0
    assert m[1, 0] == pytest.approx(5 / 15)


def test_prediction_matching_two_gt_parts():
    # pred covers GT A (0..10) and GT B (10..20) half each: IoU = 10/20 = 0.5 with each
    sm = evaluate_sets([r(0, 20)], [REV_Z], [1, 2], [r(0, 10), r(10, 20)], [REV_Z, REV_Z], VERTS, CFG)
    s25, s50 = summarize(sm.counts["0.25"]), summarize(sm.counts["0.5"])
    assert s25["precision"] == 1.0 and s25["recall"] == 1.0  # one pred is TP; both GT parts matched
    assert s25["f1"] == 1.0
    assert sm.counts["0.25"].tp_pred == 1 and sm.counts["0.25"].type_ok == 1  # articulation counted once
    # IoU must be strictly > tau: 0.5 is not > 0.5
    assert s50["precision"] == 0.0 and s50["recall"] == 0.0 and s50["f1"] == 0.0
    assert s50["joint_acc"] is None and s50["oe"] is None


def test_precision_recall_f1_and_mod_hand_computed():
    gt_sets = [r(0, 10), r(20, 30), r(40, 50), r(60, 70)]
    gt_arts = [
        REV_Z,                                                                   # diag 9 -> MD limit 2.25
        Articulation(joint_type="revolute", axis=[0, 0, 1], origin=[25, 0, 0]),  # diag 9
        PRI_X,
        Articulation(joint_type="revolute", axis=[1, 0, 0], origin=[0, 0, 0]),  # horizontal
    ]
    pred_sets = [r(0, 10), r(20, 30), r(40, 48), r(60, 70), r(80, 90)]
    pred_arts = [
        Articulation(joint_type="revolute", axis=[0, 0, -1], origin=[1, 0, 5]),  # OE 0, MD 1 < 2.25 -> MOD
        Articulation(joint_type="revolute", axis=[0, np.sin(np.radians(20)), np.cos(np.radians(20))], origin=[25, 0, 0]),  # OE 20 -> M only
        Articulation(joint_type="prismatic", axis=[1, 0, 0], origin=[9, 9, 9]),  # prismatic: MD skipped -> MOD
        REV_Z,  # vertical vs horizontal GT: wrong type
        PRI_X,  # FP
    ]
    sm = evaluate_sets(pred_sets, pred_arts, [1, 2, 3, 4], gt_sets, gt_arts, VERTS, CFG)
    s = summarize(sm.counts["0.5"])
    assert s["precision"] == pytest.approx(4 / 5)
    assert s["recall"] == pytest.approx(1.0)
    assert s["f1"] == pytest.approx(2 * 0.8 / 1.8)
    assert s["joint_acc"] == pytest.approx(3 / 4)
    assert s["oe"] == pytest.approx((0 + 20 + 0) / 3)
    assert s["md"] == pytest.approx((1 + 0) / 2)  # revolute correct-type matches only
    assert (s["pdet"], s["m"], s["mo"], s["mod"]) == pytest.approx((1.0, 0.75, 0.5, 0.5))
    # part 3 at IoU 8/10 = 0.8: still matched at 0.5
    row = [p for p in sm.parts if p["tau"] == 0.5 and p["gt_part"] == 3][0]
    assert row["iou"] == pytest.approx(0.8) and row["mod"] is True and row["md"] is None


def test_md_fails_beyond_quarter_diagonal():
    far = Articulation(joint_type="revolute", axis=[0, 0, 1], origin=[2.3, 0, 0])  # 2.3 > 0.25 * 9
    sm = evaluate_sets([r(0, 10)], [far], [1], [r(0, 10)], [REV_Z], VERTS, CFG)
    s = summarize(sm.counts["0.25"])
    assert (s["m"], s["mo"], s["mod"]) == (1.0, 1.0, 0.0)
    assert s["md"] == pytest.approx(2.3)


def test_empty_predictions():
    sm = evaluate_sets([], [], [1], [r(0, 10)], [REV_Z], VERTS, CFG)
    s = summarize(sm.counts["0.25"])
    assert s["precision"] is None and s["recall"] == 0.0 and s["f1"] == 0.0
    assert s["joint_acc"] is None and s["mod"] == 0.0


def test_empty_gt():
    sm = evaluate_sets([r(0, 10)], [REV_Z], [], [], [], VERTS, CFG)
    s = summarize(sm.counts["0.5"])
    assert s["precision"] == 0.0 and s["recall"] is None and s["f1"] == 0.0 and s["pdet"] is None


def test_both_empty_gives_null_not_zero():
    sm = evaluate_sets([], [], [], [], [], VERTS, CFG)
    assert all(v is None for v in summarize(sm.counts["0.25"]).values())


def test_aggregate_pools_counts_not_means():
    a = evaluate_sets([r(0, 10)], [REV_Z], [1], [r(0, 10)], [REV_Z], VERTS, CFG, scene="a")  # 1/1
    b = evaluate_sets([r(0, 10), r(50, 60), r(70, 80)], [REV_Z] * 3, [1], [r(0, 10)], [REV_Z], VERTS, CFG, scene="b")  # 1/3
    agg = aggregate([a, b])["0.25"]
    assert agg["precision"] == pytest.approx(2 / 4)  # pooled, not mean(1, 1/3) = 2/3
    d = to_json_dict([a, b])
    assert set(d["aggregate"]) == {"0.25", "0.5"}
    assert set(d["aggregate"]["0.5"]) == {"precision", "recall", "f1", "joint_acc", "md", "oe", "pdet", "m", "mo", "mod"}
    assert [s["scene"] for s in d["scenes"]] == ["a", "b"]
    assert d["scenes"][1]["0.25"]["precision"] == pytest.approx(1 / 3)
