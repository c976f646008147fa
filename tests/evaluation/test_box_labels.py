"""Hand-computed cases for the 2D box-label evaluation (no dataset, no rendering beyond a 2-triangle wall)."""

import json

import numpy as np
import pytest

from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.metrics.box_labels import (
    BoxLabels, FrameLabels, box_cover, box_iou, joint_class_of, load_box_labels, match_boxes, visible_box,
)


def test_box_iou_hand_values():
    assert box_iou((0, 0, 10, 10), (0, 0, 10, 10)) == pytest.approx(1.0)
    # overlap 5x10 = 50, union 100 + 100 - 50 = 150
    assert box_iou((0, 0, 10, 10), (5, 0, 15, 10)) == pytest.approx(50 / 150)
    # nested: 4x4 inside 10x10 -> 16 / 100
    assert box_iou((3, 3, 7, 7), (0, 0, 10, 10)) == pytest.approx(0.16)
    assert box_iou((0, 0, 10, 10), (10, 0, 20, 10)) == 0.0  # touching edges
    assert box_iou(None, (0, 0, 1, 1)) == 0.0


def test_box_cover_is_fraction_of_inner():
    assert box_cover((0, 0, 10, 10), (5, 0, 100, 100)) == pytest.approx(0.5)
    assert box_cover((0, 0, 10, 10), (0, 0, 10, 10)) == pytest.approx(1.0)


def _labels() -> BoxLabels:
    # two frames; front A labelled in both, B only in f1; one ignore box in f2
    return BoxLabels({
        "f1": FrameLabels({"A": (0, 0, 10, 10), "B": (20, 0, 30, 10)}),
        "f2": FrameLabels({"A": (0, 0, 10, 10)}, ignore=((50, 50, 60, 60),)),
    }, (64, 48))


def test_matching_is_one_to_one_and_uses_mean_over_labelled_frames():
    boxes = {
        # p1 fits A in f1 (1.0) and half of it in f2 (50/150): mean 0.667 -> found
        "p1": {"f1": (0, 0, 10, 10), "f2": (5, 0, 15, 10)},
        # p2 fits A exactly in both frames (1.0) but is also the only part near B: Hungarian gives A to p2, B to p3
        "p2": {"f1": (0, 0, 10, 10), "f2": (0, 0, 10, 10)},
        "p3": {"f1": (20, 0, 30, 12), "f2": None},  # B: 100 / 120
        "p4": {"f1": None, "f2": (51, 51, 59, 65)},  # 8x9 of its 8x14 box inside the ignore box = 0.64 -> ignored
        "p5": {"f1": (40, 40, 44, 44), "f2": None},  # visible, matches nothing -> false part
        "p6": {"f1": None, "f2": None},  # never visible in a labelled frame
    }
    r = match_boxes(boxes, _labels(), iou_threshold=0.5)
    by = {f.front_id: f for f in r.fronts}
    assert by["A"].found and by["A"].part == "p2" and by["A"].iou == pytest.approx(1.0)
    assert by["B"].found and by["B"].part == "p3" and by["B"].iou == pytest.approx(100 / 120)
    assert r.n_found == 2 and r.n_fronts == 2
    assert sorted(r.false_parts) == ["p1", "p5"]  # p1 lost A to p2: a duplicate counts as false
    assert r.ignored_parts == ["p4"] and r.unseen_parts == ["p6"]


def test_part_missing_in_a_labelled_frame_scores_zero_there():
    # A labelled in f1 and f2; the part is visible only in f1 -> mean (1 + 0) / 2 = 0.5
    r = match_boxes({"p": {"f1": (0, 0, 10, 10), "f2": None}}, _labels(), iou_threshold=0.5)
    a = next(f for f in r.fronts if f.front_id == "A")
    assert a.found and a.iou == pytest.approx(0.5) and a.per_frame_iou == {"f1": 1.0, "f2": 0.0}
    r = match_boxes({"p": {"f1": (0, 0, 10, 10), "f2": None}}, _labels(), iou_threshold=0.51)
    assert r.n_found == 0 and r.false_parts == ["p"]
    a = next(f for f in r.fronts if f.front_id == "A")
    assert not a.found and a.part == "p" and a.iou == pytest.approx(0.5)  # still reported, for diagnosis


def test_merged_part_reports_its_iou_with_the_other_front():
    # one part spanning A and B in f1: box (0,0,30,10) -> IoU 1/3 with each, not found at 0.5
    r = match_boxes({"m": {"f1": (0, 0, 30, 10), "f2": (0, 0, 30, 10)}}, _labels(), iou_threshold=0.3)
    found = [f for f in r.fronts if f.found]
    assert len(found) == 1 and found[0].other_iou == pytest.approx(1 / 3)


def test_joint_class_uses_45_degrees_to_the_ground():
    assert joint_class_of("revolute", (0, 0, 1)) == "revolute_vertical"
    assert joint_class_of("revolute", (1, 0, 0.9)) == "revolute_horizontal"
    assert joint_class_of("revolute", (0, 1, 1.1)) == "revolute_vertical"
    assert joint_class_of("prismatic", (1, 0, 0)) == "prismatic"


def _frame() -> Frame:
    # camera at the origin looking along +y world (OpenCV: x right, y down, z forward), world z up
    c2w = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], float)
    return Frame(frame_id="f1", rgb=ImageRef(path="x.jpg", kind="jpg"), pose=c2w,
                 intrinsics=Intrinsics(fx=50, fy=50, cx=32, cy=24, width=64, height=48))


def test_visible_box_projects_and_drops_occluded_vertices():
    f = _frame()
    # square at y = 2 m (z-depth 2): x = -+0.2 -> u = 32 -+ 50 * 0.2 / 2 = 27, 37; z = +-0.1 -> v = 24 -+ 2.5
    sq = np.array([[x, 2.0, z] for x in (-0.2, 0.2) for z in (-0.1, 0.1)])
    b = visible_box(sq, f, None, min_visible=1)
    assert b == pytest.approx((27.0, 21.5, 37.0, 26.5))
    # a scan surface at 1 m depth covering the left half of the image hides the left vertices
    depth = np.zeros((48, 64), np.float32)
    depth[:, :32] = 1.0
    b = visible_box(sq, f, depth, depth_tol=0.03, min_visible=1)
    assert b == pytest.approx((37.0, 21.5, 37.0, 26.5))
    # within the 3 cm tolerance of the surface the vertex still counts
    depth[:, :32] = 1.99
    assert visible_box(sq, f, depth, depth_tol=0.03, min_visible=1) == pytest.approx((27.0, 21.5, 37.0, 26.5))
    assert visible_box(sq, f, depth, min_visible=5) is None  # fewer than 5 vertices: not visible


def test_load_box_labels_rejects_inverted_boxes(tmp_path):
    p = tmp_path / "l.json"
    p.write_text(json.dumps({"image_size": [64, 48], "frames": {"f1": {"fronts": {"A": [0, 0, 10, 10]}, "ignore": [[1, 1, 2, 2]]}}}))
    lab = load_box_labels(p)
    assert lab.front_ids == ["A"] and lab.frames["f1"].ignore == ((1.0, 1.0, 2.0, 2.0),)
    p.write_text(json.dumps({"frames": {"f1": {"fronts": {"A": [10, 0, 0, 10]}}}}))
    with pytest.raises(ValueError, match="f1/A"):
        load_box_labels(p)


def test_shipped_redkitchen_labels_are_well_formed():
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "data" / "redkitchen_fronts.json"
    for to_projection in (False, True):
        lab = load_box_labels(path, to_projection=to_projection)
        assert lab.front_ids == ["B1", "B2", "B3", "B4", "L1", "L2", "L3", "R1", "R2"]
        assert 6 <= len(lab.frames) <= 10
        W, H = lab.image_size
        for fl in lab.frames.values():
            assert fl.render_to_photo is not None
            for b in list(fl.fronts.values()) + list(fl.ignore):
                assert 0 <= b[0] < b[2] <= W and 0 <= b[1] < b[3] <= H


def test_render_to_photo_affine_maps_boxes_into_the_projection(tmp_path):
    # photo = 0.5 * render + (10, 20): a photo box (20, 30, 40, 50) is the render box (20, 20, 60, 60)
    p = tmp_path / "l.json"
    p.write_text(json.dumps({"image_size": [100, 100], "frames": {"f1": {
        "fronts": {"A": [20, 30, 40, 50]}, "ignore": [[10, 20, 12, 22]], "render_to_photo": [[0.5, 0, 10], [0, 0.5, 20]]}}}))
    lab = load_box_labels(p)
    assert lab.frames["f1"].fronts["A"] == pytest.approx((20, 20, 60, 60))
    assert lab.frames["f1"].ignore[0] == pytest.approx((0, 0, 4, 4))
    p.write_text(p.read_text().replace("[10, 20, 12, 22]", "[0, 10, 12, 22]"))  # maps to x0 = -20: clipped to the image
    assert load_box_labels(p).frames["f1"].ignore[0] == pytest.approx((0, 0, 4, 4))
    assert load_box_labels(p, to_projection=False).frames["f1"].fronts["A"] == pytest.approx((20, 30, 40, 50))
