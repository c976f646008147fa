"""Hand-made orthophotos for the heuristic's image-path tests."""

from __future__ import annotations

import numpy as np

from react3d_core.perception.heuristic.orthophoto import Orthophoto
from react3d_core.perception.heuristic.planes import Plane


def flat_ortho(img: np.ndarray, res: float = 0.004) -> Orthophoto:
    """An orthophoto ``img`` of the plane y = 0 facing -y (u along x, top at z = rows x ``res``), every
    pixel seen by 5 views."""
    h, w = img.shape[:2]
    plane = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.zeros(0, np.int64),
                  (0.0, w * res), (0.0, h * res), w * h * res * res)
    return Orthophoto(plane, img.astype(np.float32), np.full((h, w), 5, np.int32), 0.0, h * res, res)


def oven_door_image() -> tuple[np.ndarray, np.ndarray]:
    """An oven's glass door, 0.56 x 0.8 m (140 x 200 px at 4 mm), and its bars in the scan: the bar on the top
    rail stands out (rows 30-38, cols 21-111); the pane's edge is a dark line 2 px wide (rows 48-49, cols
    30-122; the pane painted its frame's colour, as fill_panes does); a shaded patch 3.6 x 13.6 cm on the left
    stile (rows 138-171, cols 11-19) reads as a vertical handle by colour alone."""
    rng = np.random.default_rng(5)
    img = np.full((200, 140, 3), 0.85, np.float32) + rng.normal(0, 0.003, (200, 140, 3)).astype(np.float32)
    bars = np.zeros((200, 140), bool)
    img[30:39, 21:112] = 0.6
    bars[30:39, 21:112] = True
    img[48:50, 30:123] = 0.45
    img[138:172, 11:20] = 0.55
    return img, bars
