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
