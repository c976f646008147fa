"""OPDMulti JSON contract: a fake HTTP endpoint and a fake command, predictions -> ArticulationPrediction."""

from __future__ import annotations

import base64
import json
import shlex
import sys

import cv2
import numpy as np
import pytest

from react3d_core.errors import StageError
from react3d_models.opdmulti import OPDMultiClient, decode_mask, encode_png


def _png(mask: np.ndarray) -> str:
    ok, buf = cv2.imencode(".png", mask.astype(np.uint8) * 255)
    assert ok
    return base64.b64encode(buf.tobytes()).decode()


def _predictions(frame_id: str) -> dict:
    half = np.zeros((30, 40), bool)
    half[5:15, 10:20] = True  # at half resolution -> rows 10..29, cols 20..39 at 60x80
    return {"predictions": [
        {"frame_id": frame_id, "joint_type": "rotation", "axis": [0, 0, 2], "origin": [0.1, 0.2, 1.5], "score": 0.9,
         "mask_png_base64": _png(half)},
        {"frame_id": frame_id, "joint_type": "prismatic", "axis": [1, 0, 0], "origin_px": [40, 30], "score": 0.8,
         "box": [0, 0, 8, 4]},
        {"frame_id": frame_id, "joint_type": "hinge", "axis": [0, 1, 0], "score": 0.9, "box": [0, 0, 8, 4]},
        {"frame_id": frame_id, "joint_type": "revolute", "axis": [0, 1, 0], "score": 0.1, "box": [0, 0, 8, 4]},
        {"frame_id": "other", "joint_type": "revolute", "axis": [0, 1, 0], "score": 0.9, "box": [0, 0, 8, 4]},
        {"frame_id": frame_id, "joint_type": "revolute", "axis": [0, 0, 0], "score": 0.9, "box": [0, 0, 8, 4]},
    ]}


def _check(preds: list) -> None:
    assert len(preds) == 1 and len(preds[0]) == 2
    rev, pri = preds[0]
    assert rev.joint_type == "revolute" and rev.axis_cam == (0.0, 0.0, 1.0) and rev.origin_cam == (0.1, 0.2, 1.5)
    expect = np.zeros((60, 80), bool)
    expect[10:30, 20:40] = True
    assert rev.mask.shape == (60, 80) and (rev.mask == expect).all()
    assert pri.joint_type == "prismatic" and pri.origin_px == (40.0, 30.0) and pri.origin_cam is None
    assert pri.mask.sum() == 32 and pri.mask[:4, :8].all()


def test_http_endpoint_contract(fake_server, make_frame, make_image):
    def handler(i, body):
        f = body["frames"][0]
        img = cv2.imdecode(np.frombuffer(base64.b64decode(f["image_png_base64"]), np.uint8), cv2.IMREAD_COLOR)
        assert img.shape == (f["height"], f["width"], 3) and np.asarray(f["K"]).shape == (3, 3)
        return 200, json.dumps(_predictions(f["frame_id"])).encode(), 0

    srv = fake_server(handler)
    client = OPDMultiClient(srv.url + "/predict", timeout_s=5, min_score=0.5, backoff_s=0.01)
    _check(client.predict([make_frame("f0", 60, 80)], [make_image(60, 80, 0)]))
    assert srv.requests[0]["path"] == "/predict" and srv.requests[0]["body"]["version"] == 1


def test_command_contract(tmp_path, make_frame, make_image):
    reply = tmp_path / "reply.json"
    reply.write_text(json.dumps(_predictions("f0")))
    script = tmp_path / "opd.py"
    script.write_text("import json, sys\nreq = json.load(sys.stdin)\nassert req['frames'][0]['frame_id'] == 'f0'\n"
                      f"sys.stdout.write(open({str(reply)!r}).read())\n")
    client = OPDMultiClient(f"{shlex.quote(sys.executable)} {shlex.quote(str(script))}", timeout_s=30, min_score=0.5)
    _check(client.predict([make_frame("f0", 60, 80)], [make_image(60, 80, 0)]))


def test_failures_are_one_line_stage_errors(fake_server, tmp_path, make_frame, make_image):
    fr, im = [make_frame("f0", 60, 80)], [make_image(60, 80, 0)]
    srv = fake_server(lambda i, body: (200, b'{"no": "predictions"}', 0))
    with pytest.raises(StageError, match="predictions"):
        OPDMultiClient(srv.url, 5, 0.5).predict(fr, im)
    bad = fake_server(lambda i, body: (500, b"", 0))
    with pytest.raises(StageError, match="failed"):
        OPDMultiClient(bad.url, 5, 0.5, retries=1, backoff_s=0.01).predict(fr, im)
    assert len(bad.requests) == 2
    with pytest.raises(StageError, match="not found"):
        OPDMultiClient(str(tmp_path / "no-such-opdmulti"), 5, 0.5).predict(fr, im)


def test_png_round_trip():
    m = np.zeros((7, 9), bool)
    m[2:5, 3:8] = True
    assert (decode_mask(_png(m), 7, 9) == m).all()
    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0] = 255  # red in RGB must stay red
    back = cv2.imdecode(np.frombuffer(base64.b64decode(encode_png(rgb)), np.uint8), cv2.IMREAD_COLOR)
    assert (back[..., 2] == 255).all() and (back[..., 0] == 0).all()


def test_prediction_to_world_hand_computed(make_frame):
    """Camera 90 deg about world z, at (1, 2, 0.5): camera x -> world y, so axis (1,0,0) -> (0,1,0) and
    origin (0.5, 0, 2) -> R @ o + t = (0, 0.5, 2) + (1, 2, 0.5) = (1, 2.5, 2.5)."""
    from react3d_core.data.frames import Frame
    from react3d_core.data.masks import ArticulationPrediction
    from react3d_models.opdmulti import prediction_to_world

    pose = np.array([[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 0.5], [0, 0, 0, 1]], float)
    f = Frame(**{**make_frame("w", 4, 4).model_dump(), "pose": pose})
    pred = ArticulationPrediction(frame_id="w", mask=np.ones((4, 4), bool), joint_type="revolute",
                                  axis_cam=(1.0, 0.0, 0.0), origin_cam=(0.5, 0.0, 2.0))
    axis, origin = prediction_to_world(pred, f)
    np.testing.assert_allclose(axis, [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(origin, [1, 2.5, 2.5], atol=1e-12)
    only_px = pred.model_copy(update={"origin_cam": None, "origin_px": (2.0, 2.0)})
    assert prediction_to_world(only_px, f)[1] is None
