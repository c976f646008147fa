"""M-LSD line segments in a colour image, through a TensorFlow Lite interpreter (no torch, no pickles).

M-LSD ("Towards Light-weight and Real-time Line Segment Detection", Gu et al., AAAI 2022; Apache-2.0)
predicts, on a 256 x 256 grid over its 512 x 512 input, candidate segment centres with scores and a
displacement map from each centre to the segment's two end points. The heuristic's opt-in line evidence
(``perception.heuristic.lines``; react3d_core/perception/heuristic/line_evidence.py) calls the detector
built here, per frame, and receives the segments as plain arrays.

The interpreter comes from the ``ai-edge-litert`` package (imported when a detector is built, never at
import). The weights are a file of the authors' repository; its SHA-256 is checked before it is read, so
a truncated or other file is one clear error, not a crash inside the interpreter.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from react3d_core.config.heuristic import LineConfig
from react3d_core.errors import ConfigError

INPUT_PX = 512  # the model's square input
GRID_PX = 256  # its output grid: one cell per 2 input px
WEIGHTS_ENV = "REACT3D_MLSD_WEIGHTS"  # where the weights are when perception.heuristic.lines.weights is null
SOURCE = ("github.com/navervision/mlsd, folder tflite_models/, commit 453cafa09467d0272760578d35c1fda38e8895a5 "
          "(Apache-2.0; keep its LICENSE with the file)")
# the files of that commit this adapter reads (M-LSD tiny and large, fp16 tflite) -> their SHA-256
WEIGHTS_SHA256 = {
    "M-LSD_512_tiny_fp16.tflite": "e869f90601ffa263f21ac47e09ff0d65dc936d1aeb47126b8499d5504adfb100",
    "M-LSD_512_large_fp16.tflite": "34c470216a905c4850771ce2bfc5e13079d99799aaa5726dd51a985fb62b0b8b",
}
_CHUNK = 1 << 20  # bytes hashed per read
_ONES = 1.0  # the fourth input channel the model was trained with
# the model's outputs told apart by rank: centres (1, M, 2), scores (1, M), displacement map (1, G, G, 4)
_POINTS, _SCORES, _DISPLACEMENT = 3, 2, 4
_XY = 2  # coordinates of a point


class LineDetectorUnavailable(ConfigError):
    """The detector's runtime or weights are missing; the message says where to get them."""


def sha256(path: Path) -> str:
    """Hex SHA-256 of a file, read in chunks."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def weights_path(cfg: LineConfig) -> Path:
    """The configured weights file (``weights``, else $REACT3D_MLSD_WEIGHTS), checked: it exists and is one
    of the files in ``WEIGHTS_SHA256`` byte for byte."""
    given = cfg.weights or os.environ.get(WEIGHTS_ENV)
    if not given:
        raise LineDetectorUnavailable(
            f"perception.heuristic.lines is enabled but no M-LSD weights are given: set perception.heuristic.lines.weights "
            f"(or ${WEIGHTS_ENV}) to M-LSD_512_tiny_fp16.tflite from {SOURCE}")
    path = Path(given).expanduser()
    if not path.is_file():
        raise LineDetectorUnavailable(f"{path}: M-LSD weights not found; get M-LSD_512_tiny_fp16.tflite from {SOURCE}")
    digest = sha256(path)
    if digest not in WEIGHTS_SHA256.values():
        raise LineDetectorUnavailable(
            f"{path}: not an M-LSD tflite file this adapter knows (SHA-256 {digest[:16]}...); use "
            f"{' or '.join(WEIGHTS_SHA256)} from {SOURCE}")
    return path


def decode_segments(points: np.ndarray, scores: np.ndarray, displacement: np.ndarray, width: int, height: int,
                    min_score: float, min_length_px: float) -> np.ndarray:
    """Segments (N, 5: x0, y0, x1, y1 in px of a ``width`` x ``height`` image, score) from the model's outputs:
    centres ``points`` (M, 2) as (row, column) on the output grid, their ``scores`` (M,), and the displacement
    map (G, G, 4) giving, at a centre (y, x), the end points (x + d0, y + d1) and (x + d2, y + d3). Centres
    scoring at most ``min_score`` and segments at most ``min_length_px`` long (px of the 512 px input) are dropped."""
    g = displacement.shape[0]
    y = np.clip(points[:, 0].astype(int), 0, g - 1)
    x = np.clip(points[:, 1].astype(int), 0, g - 1)
    d = displacement[y, x].astype(np.float64)
    seg = np.stack([x + d[:, 0], y + d[:, 1], x + d[:, 2], y + d[:, 3]], 1)
    scale = INPUT_PX / g  # output grid -> input px
    length = np.hypot(d[:, 2] - d[:, 0], d[:, 3] - d[:, 1]) * scale
    keep = (scores > min_score) & (length > min_length_px)
    seg = seg[keep] * scale
    seg[:, 0::_XY] *= width / INPUT_PX
    seg[:, 1::_XY] *= height / INPUT_PX
    return np.concatenate([seg, scores[keep, None].astype(np.float64)], 1).astype(np.float32)


def model_input(rgb: np.ndarray) -> np.ndarray:
    """The model's input for an RGB image (H, W, 3; 0-255): resized to 512 x 512, a channel of ones
    appended, float32 (1, 512, 512, 4); no other normalisation."""
    small = cv2.resize(rgb, (INPUT_PX, INPUT_PX), interpolation=cv2.INTER_AREA).astype(np.float32)
    return np.concatenate([small, np.full(small.shape[:2] + (1,), _ONES, np.float32)], -1)[None]


class MlsdDetector:
    """``detector(rgb) -> (N, 5)`` segments (x0, y0, x1, y1, score) in the image's pixels."""

    def __init__(self, path: Path, cfg: LineConfig) -> None:
        try:
            from ai_edge_litert.interpreter import Interpreter
        except ImportError:
            raise LineDetectorUnavailable(
                "perception.heuristic.lines needs the TensorFlow Lite interpreter: pip install ai-edge-litert") from None
        self.cfg = cfg
        self.interpreter = Interpreter(model_path=str(path), num_threads=cfg.threads)
        self.interpreter.allocate_tensors()
        self.input = self.interpreter.get_input_details()[0]["index"]
        self.outputs = {len(o["shape"]): o["index"] for o in self.interpreter.get_output_details()}
        if sorted(self.outputs) != sorted((_POINTS, _SCORES, _DISPLACEMENT)):
            raise LineDetectorUnavailable(f"{path}: not an M-LSD model (outputs of ranks {sorted(self.outputs)})")

    def __call__(self, rgb: np.ndarray) -> np.ndarray:
        h, w = rgb.shape[:2]
        self.interpreter.set_tensor(self.input, model_input(rgb))
        self.interpreter.invoke()
        get = self.interpreter.get_tensor
        return decode_segments(get(self.outputs[_POINTS])[0], get(self.outputs[_SCORES])[0],
                               get(self.outputs[_DISPLACEMENT])[0], w, h, self.cfg.min_score, self.cfg.min_length_px)


def load_line_detector(cfg: LineConfig) -> Callable[[np.ndarray], np.ndarray]:
    """The M-LSD detector ``perception.heuristic.lines`` names; LineDetectorUnavailable (one line) when the
    weights or the interpreter are missing."""
    return MlsdDetector(weights_path(cfg), cfg)
