"""The M-LSD line-segment adapter (react3d_models/line_segments.py) and the heuristic's opt-in use of it.

Decoding and input building are checked by hand on made-up model outputs; the weights' SHA-256, the
detector on a synthetic image with known lines and the opt-in path end to end run only where the
weights (``../shared/models/mlsd`` or $REACT3D_MLSD_WEIGHTS) and the ``ai-edge-litert`` interpreter are
present, and skip otherwise. Nothing is downloaded."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from react3d_core.config.heuristic import HeuristicConfig, LineConfig
from react3d_core.errors import ConfigError
from react3d_models.line_segments import (WEIGHTS_ENV, WEIGHTS_SHA256, LineDetectorUnavailable, decode_segments,
                                          model_input, sha256, weights_path)

REPO = Path(__file__).resolve().parents[2]
SHARED = (REPO / ".." / "shared" / "models" / "mlsd").resolve()
TINY = Path(os.environ.get(WEIGHTS_ENV) or SHARED / "M-LSD_512_tiny_fp16.tflite")
HAVE_WEIGHTS = TINY.is_file()
HAVE_RUNTIME = importlib.util.find_spec("ai_edge_litert") is not None
needs_detector = pytest.mark.skipif(not (HAVE_WEIGHTS and HAVE_RUNTIME),
                                    reason="needs the M-LSD tflite weights and the ai-edge-litert package")


def test_decode_segments_hand_computed() -> None:
    """Centre (row 10, column 20) with displacement (-5, 0, 5, 30): ends (15, 10) and (25, 40) on the 256 grid,
    31.6 grid px = 63 input px long; x2 to the 512 input, then x 640/512 and x 480/512 to the image:
    (37.5, 18.75, 62.5, 75.0). A centre scoring 0.05 and a 5.7 px segment are dropped."""
    disp = np.zeros((256, 256, 4), np.float32)
    disp[10, 20] = (-5, 0, 5, 30)
    disp[5, 5] = (1, 1, -1, -1)
    disp[100, 50] = (-20, 0, 20, 0)
    points = np.array([[10, 20], [100, 50], [5, 5]], np.int32)
    scores = np.array([0.9, 0.05, 0.8], np.float32)
    seg = decode_segments(points, scores, disp, 640, 480, min_score=0.1, min_length_px=40.0)
    assert seg.shape == (1, 5)
    assert seg[0] == pytest.approx([37.5, 18.75, 62.5, 75.0, 0.9])
    # the length threshold is in input px: at 64 px the same segment (63.2) goes
    assert len(decode_segments(points, scores, disp, 640, 480, 0.1, 64.0)) == 0
    assert len(decode_segments(points[:0], scores[:0], disp, 640, 480, 0.1, 40.0)) == 0


def test_model_input_is_rgb_resized_with_a_channel_of_ones() -> None:
    img = np.zeros((480, 640, 3), np.uint8)
    img[..., 0], img[..., 1], img[..., 2] = 200, 100, 7
    x = model_input(img)
    assert x.shape == (1, 512, 512, 4) and x.dtype == np.float32
    assert x[0, 100, 100].tolist() == [200.0, 100.0, 7.0, 1.0]   # 0-255, no normalisation, ones appended


@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared/models/mlsd is not here")
def test_the_weight_files_are_the_ones_named() -> None:
    """Each file the adapter knows, where present, has the SHA-256 written down for it (and the README's)."""
    found = [name for name in WEIGHTS_SHA256 if (SHARED / name).is_file()]
    assert found, "no M-LSD tflite file in ../shared/models/mlsd"
    for name in found:
        assert sha256(SHARED / name) == WEIGHTS_SHA256[name]
        assert weights_path(LineConfig(weights=str(SHARED / name))) == SHARED / name


def test_missing_or_wrong_weights_are_one_line_saying_where_to_get_them(tmp_path: Path,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(WEIGHTS_ENV, raising=False)
    with pytest.raises(LineDetectorUnavailable) as e:
        weights_path(LineConfig(enabled=True))
    msg = str(e.value)
    assert "\n" not in msg and "perception.heuristic.lines.weights" in msg and WEIGHTS_ENV in msg
    assert "github.com/navervision/mlsd" in msg and "453cafa09467d0272760578d35c1fda38e8895a5" in msg
    missing = tmp_path / "nope.tflite"
    with pytest.raises(LineDetectorUnavailable, match=f"^{missing}: M-LSD weights not found; get M-LSD_512_tiny"):
        weights_path(LineConfig(weights=str(missing)))
    other = tmp_path / "other.tflite"
    other.write_bytes(b"not a model")
    with pytest.raises(LineDetectorUnavailable, match=f"^{other}: not an M-LSD tflite file"):
        weights_path(LineConfig(weights=str(other)))
    monkeypatch.setenv(WEIGHTS_ENV, str(missing))   # the environment variable is read when the field is null
    with pytest.raises(LineDetectorUnavailable, match="nope.tflite: M-LSD weights not found"):
        weights_path(LineConfig())
    assert issubclass(LineDetectorUnavailable, ConfigError)


def test_nothing_loads_at_import() -> None:
    """In a fresh interpreter: the heuristic and the adapter import without the tflite interpreter or torch;
    with the section off (the default) the heuristic never imports the adapter."""
    code = ("import sys, json\n"
            "import react3d_core.perception.heuristic, react3d_core.perception.heuristic.line_evidence\n"
            "before = 'react3d_models.line_segments' in sys.modules\n"
            "import react3d_models.line_segments\n"
            "print(json.dumps({'adapter_before': before, 'litert': 'ai_edge_litert' in sys.modules, "
            "'torch': 'torch' in sys.modules}))")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == {"adapter_before": False, "litert": False, "torch": False}


def test_enabled_without_weights_is_a_config_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """The heuristic's loader hands the section to the adapter: no weights -> the adapter's one line."""
    from react3d_core.perception.heuristic.backend import load_line_detector

    monkeypatch.delenv(WEIGHTS_ENV, raising=False)
    with pytest.raises(ConfigError, match="no M-LSD weights are given"):
        load_line_detector(HeuristicConfig(lines={"enabled": True, "detector": "mlsd"}).lines)


@needs_detector
def test_the_detector_finds_known_lines_in_a_synthetic_image() -> None:
    """A 640 x 480 light image with a dark 4 px horizontal bar (y 238-241, x 360-599) and a vertical one
    (x 298-301, y 80-399): segments along both, in image pixels."""
    from react3d_models.line_segments import load_line_detector

    img = np.full((480, 640, 3), 200, np.uint8)
    img[238:242, 360:600] = 40
    img[80:400, 298:302] = 40
    seg = load_line_detector(LineConfig(weights=str(TINY)))(img)
    assert seg.shape[1] == 5 and len(seg) >= 2
    horiz = [s for s in seg if abs(s[1] - 240) < 4 and abs(s[3] - 240) < 4]
    assert horiz and min(min(s[0], s[2]) for s in horiz) == pytest.approx(360, abs=10)
    assert max(max(s[0], s[2]) for s in horiz) == pytest.approx(600, abs=10)
    vert = [s for s in seg if abs(s[0] - 300) < 4 and abs(s[2] - 300) < 4]
    assert vert and max(abs(s[3] - s[1]) for s in vert) > 200


@needs_detector
def test_the_opt_in_path_end_to_end() -> None:
    """The heuristic built from its config with ``lines.enabled`` on a small seamless two-door scene: the
    detector runs on the views it picks, the doors' seam at x = 0.6 m is supported by several of them, and
    the two doors are found."""
    from tests.perception.heuristic.test_classic_lines import assert_seam_supported_and_two_doors

    assert_seam_supported_and_two_doors(HeuristicConfig(lines={"enabled": True, "detector": "mlsd", "weights": str(TINY)}))
