"""Parts the scan lacks (GT box + scan coverage): front-box IoU by hand, the evaluation's switch to it,
the Articulate3D round trip of the two optional keys, and the ground truth scored as a prediction."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from react3d_core.config.metrics import EvaluationConfig
from react3d_core.data.mesh import TriMesh, save_mesh
from react3d_core.data.parts import OBB, Articulation
from react3d_core.ground_truth.articulate3d import GroundTruth, GTPart, read_articulate3d, write_articulate3d
from react3d_core.metrics import gt_to_scene, run_evaluation
from react3d_core.metrics.scene_metrics import box_scored_box, evaluate_sets, front_box_iou

# a 1.0 x 0.5 front (x by z), 2 cm thick along y, centred at the origin
GT_BOX = OBB(center=(0.0, 0.0, 0.0), axes=((1.0, 0, 0), (0, 0, 1.0), (0, -1.0, 0)), extents=(1.0, 0.5, 0.02))
DOOR = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(-0.5, 0, 0), upper=1.5)


def _box(cx: float, cy: float, cz: float, ex: float, ez: float, ey: float = 0.02, yaw_deg: float = 0.0) -> OBB:
    a = np.radians(yaw_deg)
    u = (np.cos(a), np.sin(a), 0.0)
    n = (np.sin(a), -np.cos(a), 0.0)
    return OBB(center=(cx, cy, cz), axes=(u, (0, 0, 1.0), n), extents=(ex, ez, ey))


def test_front_box_iou_by_hand() -> None:
    assert front_box_iou(GT_BOX, GT_BOX) == pytest.approx(1.0)
    # shifted by half its width: overlap 0.5 x 0.5 = 0.25, union 0.5 + 0.5 - 0.25 = 0.75
    assert front_box_iou(_box(0.5, 0.0, 0.0, 1.0, 0.5), GT_BOX) == pytest.approx(1 / 3, abs=1e-6)
    # a quarter of the front (0.5 x 0.25 in one corner): 0.125 / 0.5
    assert front_box_iou(_box(-0.25, 0.0, 0.125, 0.5, 0.25), GT_BOX) == pytest.approx(0.25, abs=1e-6)
    # thickness and a plane 3 cm off do not matter within the 5 cm slab tolerance
    assert front_box_iou(_box(0.0, -0.03, 0.0, 1.0, 0.5, ey=0.04), GT_BOX) == pytest.approx(1.0, abs=1e-6)
    # a box reaching 8 cm behind the front (a whole cabinet) or a plane 10 cm off: 0
    assert front_box_iou(_box(0.0, 0.3, 0.0, 1.0, 0.5, ey=0.6), GT_BOX) == 0.0
    assert front_box_iou(_box(0.0, 0.1, 0.0, 1.0, 0.5), GT_BOX) == 0.0
    # a box turned 90 degrees about z: its outline on the front plane is 2 cm wide
    turned = _box(0.0, 0.0, 0.0, 1.0, 0.5, yaw_deg=90.0)
    assert front_box_iou(turned, GT_BOX, slab_tol=1.0) == pytest.approx(0.02 * 0.5 / 0.5, abs=1e-6)


def test_box_scored_part_matches_a_prediction_without_scan_vertices() -> None:
    cfg = EvaluationConfig()
    gt_sets = [np.zeros(0, np.int64), np.arange(10, 20)]
    preds = [np.zeros(0, np.int64), np.arange(10, 20)]
    boxes = [_box(0.1, 0.0, 0.0, 1.0, 0.5), _box(5.0, 0.0, 0.0, 1.0, 0.5)]
    verts = np.zeros((30, 3))
    sm = evaluate_sets(preds, [DOOR, DOOR], [7, 8], gt_sets, [DOOR, DOOR], verts, cfg, pred_boxes=boxes,
                       gt_boxes=[GT_BOX, None])
    c = sm.counts["0.5"]
    assert (c.tp_pred, c.gt_matched, c.n_gt, c.n_pred) == (2, 2, 2, 2)
    rows = {r["gt_part"]: r for r in sm.parts if r["tau"] == 0.5}
    # overlap 0.9 x 0.5 over 1.1 x 0.5
    assert rows[7]["iou"] == pytest.approx(0.9 / 1.1, abs=1e-6) and rows[7]["scored_by"] == "box"
    assert rows[8]["iou"] == 1.0 and rows[8]["scored_by"] == "vertices"
    assert rows[7]["diag"] == pytest.approx(np.linalg.norm([1.0, 0.5, 0.02]))
    with pytest.raises(ValueError, match="box per prediction"):
        evaluate_sets(preds, [DOOR, DOOR], [7, 8], gt_sets, [DOOR, DOOR], verts, cfg, gt_boxes=[GT_BOX, None])


def test_which_parts_are_scored_by_box() -> None:
    cfg = EvaluationConfig()
    part = GTPart(1, "cabinet.door_1", np.arange(3), np.arange(5), DOOR, obb=GT_BOX, coverage=0.3)
    assert box_scored_box(part, 5, cfg) is GT_BOX
    part.coverage = 0.8
    assert box_scored_box(part, 5, cfg) is None
    assert box_scored_box(part, 0, cfg) is GT_BOX  # no scan vertices at all
    part.obb = None
    assert box_scored_box(part, 0, cfg) is None  # nothing to score it by: vertex IoU as ever


def test_articulate3d_round_trip_of_box_and_coverage(tmp_path: Path) -> None:
    parts = [GTPart(0, "cabinet.door_1", np.array([0, 1]), np.array([0, 1, 2]), DOOR, [2], obb=GT_BOX, coverage=0.123456),
             GTPart(1, "cabinet.door_1.handle", np.array([2]), np.array([3, 4, 5])),
             GTPart(2, "cabinet", np.array([3]), np.array([6, 7, 8]))]
    write_articulate3d(tmp_path, GroundTruth("s", parts, 4, 9))
    gt = read_articulate3d(tmp_path)
    assert gt.parts[0].obb == GT_BOX and gt.parts[0].coverage == pytest.approx(0.1235)
    assert gt.parts[1].obb is None and gt.parts[1].coverage is None
    raw = json.loads((tmp_path / "s_parts.json").read_text())["data"]["annotations"]
    assert "obb" not in raw[1] and "scanCoverage" not in raw[2]  # files without them stay as they were
    raw[0]["obb"] = {"center": [0, 0]}
    (tmp_path / "s_parts.json").write_text(json.dumps({"data": {"annotations": raw}}))
    with pytest.raises(Exception, match="obb or scanCoverage"):
        read_articulate3d(tmp_path)


def test_ground_truth_with_an_empty_part_scores_perfect(tmp_path: Path) -> None:
    """A front the scan lacks entirely (no vertices, only its box) still scores as the GT's own prediction."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1], [3, 0, 0], [4, 0, 0], [4, 0, 1]], float)
    f = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6]])
    save_mesh(tmp_path / "mesh.ply", TriMesh(v, f))
    box2 = OBB(center=(3.5, 0, 0.5), axes=((1.0, 0, 0), (0, 0, 1.0), (0, -1.0, 0)), extents=(1.0, 1.0, 0.02))
    parts = [GTPart(0, "cabinet.door_1", np.array([0, 1]), np.array([0, 1, 2, 3]), DOOR),
             GTPart(1, "cabinet.door_2", np.zeros(0, np.int64), np.zeros(0, np.int64),
                    Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(3, 0, 0.5), upper=1.5), obb=box2, coverage=0.0)]
    write_articulate3d(tmp_path / "gt", GroundTruth("s", parts, 3, 7))
    gt_to_scene(read_articulate3d(tmp_path / "gt"), tmp_path / "mesh.ply", tmp_path / "pred")
    res = run_evaluation(tmp_path / "pred", tmp_path / "gt")
    a = res["aggregate"]["0.5"]
    assert (a["f1"], a["joint_acc"], a["mod"]) == (1.0, 1.0, 1.0)
