"""Straight line segments by OpenCV's LSD, a classical detector with no weights, for the line evidence.

The heuristic's line evidence (line_evidence.py, ``perception.heuristic.lines``) takes segments from any
detector that maps an RGB image to rows (x0, y0, x1, y1) in its pixels. LSD (von Gioi et al., "LSD: a Line
Segment Detector", IPOL 2012; in OpenCV as ``cv2.createLineSegmentDetector``) finds them from the image
gradient with an a-contrario test, so it needs no weights and runs in the core. It reads the grey image
lifted by ``gamma`` (< 1 spreads the dark levels): the seam between two black fronts is a line a few grey
levels deep in the raw image, which the lift makes a gradient LSD keeps. A seam is 1–2 px wide in a photo
and several views must agree on it on the plane (``lines.min_views``), so one view's texture or reflection
does not cut a front.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from ...config.heuristic import LineConfig

REFERENCE_PX = 512.0  # ``lines.min_length_px`` is given in px of an image this wide (the learned detector's input)
_LEVELS = 255.0
_SEGMENT_COLS = 4  # x0, y0, x1, y1


def lsd_segments(rgb: np.ndarray, gamma: float, min_length_px: float, detector: cv2.LineSegmentDetector | None = None
                 ) -> np.ndarray:
    """Segments (N, 4: x0, y0, x1, y1 in px of ``rgb``) at least ``min_length_px`` long (px of a 512 px wide
    image, scaled to this one's width), found by LSD on the grey image lifted to the power ``gamma``."""
    grey = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2GRAY).astype(np.float32) / _LEVELS
    lifted = (np.power(grey, gamma) * _LEVELS).astype(np.uint8)
    det = detector if detector is not None else cv2.createLineSegmentDetector()
    seg = det.detect(lifted)[0]
    if seg is None:
        return np.zeros((0, _SEGMENT_COLS), np.float32)
    seg = seg.reshape(-1, _SEGMENT_COLS).astype(np.float32)
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    return seg[length >= min_length_px * rgb.shape[1] / REFERENCE_PX]


def lsd_detector(cfg: LineConfig) -> Callable[[np.ndarray], np.ndarray]:
    """The detector ``perception.heuristic.lines`` calls per frame when ``lines.detector`` is ``lsd``."""
    det = cv2.createLineSegmentDetector()
    return lambda rgb: lsd_segments(rgb, cfg.gamma, cfg.min_length_px, det)
