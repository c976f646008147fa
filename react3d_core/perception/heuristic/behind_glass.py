"""Surfaces seen through a glass door are no fronts.

Through a glass-panel door the views (and a laser scan) reach the cabinet's inside: its side walls,
partitions and shelves are planar, lit and edged like fronts, and a shelf's lip reads as a handle. Such a
"front" lies behind a pane that the image path found on another plane (``image_fronts.framed_panes``), within a
cabinet's depth of it. Each plane's panes are kept as a region (:class:`PaneRegion`); a front most of whose
rectangle projects, along the pane plane's normal, into a pane grown by its frame, from behind that plane, is
dropped.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from .fronts import Front
from .orthophoto import Orthophoto

_SAMPLES = 5  # sample points per side of a front's rectangle (25 in all)
_UP = np.array([0.0, 0.0, 1.0])
_VERTICAL_COS = 0.5  # a front whose normal is within 60 deg of vertical is a lid, not on a vertical plane


@dataclass
class PaneRegion:
    """The panes of one plane's orthophoto, grown by ``grow`` metres (a pane's frame: what lies just
    behind the frame is seen through the pane beside it)."""

    ortho: Orthophoto
    mask: np.ndarray  # bool grid of the orthophoto

    @staticmethod
    def of(o: Orthophoto, panes: np.ndarray, grow: float) -> PaneRegion:
        px = max(0, int(round(grow / o.res)))
        m = panes.astype(np.uint8)
        if px:
            m = cv2.dilate(m, np.ones((2 * px + 1, 2 * px + 1), np.uint8))
        return PaneRegion(o, m.astype(bool))


def front_samples(f: Front, n: int = _SAMPLES) -> np.ndarray:
    """(n * n, 3) points spread over a front's rectangle (inset half a step from its edges)."""
    s = (np.arange(n) + 0.5) / n
    us = f.extent_u[0] + s * f.w
    zs = f.extent_v[0] + s * f.h
    uu, zz = np.meshgrid(us, zs)
    c = np.asarray(f.center, float)
    return c + (uu.ravel() - float(c @ f.u))[:, None] * f.u + (zz.ravel() - c[2])[:, None] * _UP


def share_behind_panes(points: np.ndarray, region: PaneRegion, min_depth: float, max_depth: float) -> float:
    """Share of ``points`` between ``min_depth`` and ``max_depth`` behind the region's plane whose foot on
    the plane falls in its (grown) panes."""
    o = region.ortho
    p = o.plane
    depth = p.d - points @ p.n  # > 0 behind the plane (the side away from the views)
    row, col, on_grid = o.pixels_of(points)
    inside = on_grid & (depth >= min_depth) & (depth <= max_depth)
    hit = np.zeros(len(points), bool)
    hit[inside] = region.mask[row[inside], col[inside]]
    return float(hit.mean()) if len(points) else 0.0


def seen_through_glass(fronts: Sequence[Front], regions: Sequence[PaneRegion], min_depth: float, max_depth: float,
                       share: float) -> list[bool]:
    """Per front: at least ``share`` of its rectangle lies ``min_depth``-``max_depth`` behind a pane of
    another plane (see module docstring). Fronts on no vertical plane (lids) are kept."""
    out = []
    for f in fronts:
        if not regions or abs(float(np.asarray(f.n_out) @ _UP)) > _VERTICAL_COS:
            out.append(False)
            continue
        pts = front_samples(f)
        out.append(any(share_behind_panes(pts, r, min_depth, max_depth) >= share for r in regions))
    return out
