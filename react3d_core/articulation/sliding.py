"""When a prismatic part may slide in its front plane (a sliding door) instead of out of it (a drawer).

A predictor's ``sliding`` flag alone is not enough: an oracle that reads a drawer's GT part with its box
(0.6 wide, 0.15 high, 0.45 deep: the thinnest spread is the height) calls it flat with an in-plane axis,
and the in-plane snap then turns the drawer 72-90 deg off its front normal. The flag is kept only where the
part's own geometry agrees:

- the predicted axis lies in the fitted front plane (more than 45 deg from the front normal): a sliding
  door's motion does, a drawer's does not;
- the front is not drawer-shaped: a vertical front lower than ``min_height_m`` with its width along the
  axis is a drawer front (sliding doors stand at least a cabinet cell tall), and a part labelled drawer
  never slides sideways.
"""

from __future__ import annotations

import numpy as np

from ..data.parts import OBB

UP = np.array([0.0, 0.0, 1.0])  # world = scan frame, z up
IN_PLANE_COS = float(np.cos(np.radians(45.0)))


def front_height(obb: OBB, front_normal: np.ndarray) -> float | None:
    """The in-plane extent of a vertical front along gravity (None for a front facing up or down)."""
    n = np.asarray(front_normal, float)
    if abs(float(n @ UP)) > 0.5:
        return None
    R, ext = obb.R, obb.extents
    k = int(np.argmax([abs(float(R[:, i] @ UP)) for i in (0, 1)]))
    return float(ext[k])


def sliding_agrees(axis: np.ndarray, obb: OBB, front_normal: np.ndarray, label: str, min_height_m: float) -> bool:
    """True when a part the predictor calls sliding can slide: axis in the front plane, not a drawer front."""
    a = np.asarray(axis, float)
    a = a / max(float(np.linalg.norm(a)), 1e-12)
    n = np.asarray(front_normal, float)
    n = n / max(float(np.linalg.norm(n)), 1e-12)
    if abs(float(a @ n)) > IN_PLANE_COS:
        return False
    if "drawer" in label.lower():
        return False
    h = front_height(obb, n)
    if h is not None and h < min_height_m:
        horizontal = abs(float(a @ UP)) < IN_PLANE_COS
        if horizontal:
            return False
    return True
