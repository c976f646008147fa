"""Round doors (a washing machine's or a dryer's porthole) from the ring standing out of a plane.

A porthole door is a ring (and a glass bowl) in front of the appliance's front plate: the ring is
no plane, the bowl is glass the scan lacks, and the cells of the plate around it are cut by nothing
that follows the door, so the plate came out as one front covering door, drawer and control strip
(free-standing tuning: 4 washing machines, none of their doors found). The ring is plain in the mesh:
faces standing a few centimetres proud of the plate, all round a circle, with nothing proud inside.
"""

from __future__ import annotations

import cv2
import numpy as np

from ...config.heuristic import PortholeConfig
from .constants import CONNECTIVITY

_SECTORS = 24  # angular sectors the ring's pixels must reach round its centre
_QUARTER = 0.25  # the radius is a quarter of the box's width plus height (their mean half)
_CORE = 1.0 - np.sqrt(3.0) / 2.0  # a disc's lines at most 0.87 r off its centre hold half its widest line


def find_portholes(proud: np.ndarray, res: float, cfg: PortholeConfig) -> list[tuple[int, int, int, int]]:
    """Boxes (r0, r1, c0, c1; grid px, end exclusive) of rings in ``proud`` (grid pixels whose surface stands
    proud of the plane) that are porthole doors: square-ish, ``cfg.diameter`` across, their pixels within
    ``cfg.band`` of the radius (a rectangular frame's corners lie at 1.41 of it), reaching ``cfg.sectors`` of the
    way round (a gap where the fused ring broke is allowed), and the inner disc (``cfg.inner`` of the
    radius) at most ``cfg.inner_max`` proud (a round boss, a clock or a lamp is a filled disc)."""
    if not proud.any():
        return []
    n, lab, stats, _ = cv2.connectedComponentsWithStats(proud.astype(np.uint8), connectivity=CONNECTIVITY)
    out: list[tuple[int, int, int, int]] = []
    lo, hi = cfg.diameter[0] / res, cfg.diameter[1] / res
    for k in range(1, n):
        c0, r0, w, h = (int(v) for v in stats[k, :4])
        if not (lo <= max(w, h) <= hi and max(w, h) <= cfg.max_aspect * min(w, h)):
            continue
        rows, cols = np.nonzero(lab[r0:r0 + h, c0:c0 + w] == k)
        cy, cx = 0.5 * (h - 1), 0.5 * (w - 1)
        rad = _QUARTER * (w + h)
        dist = np.hypot(rows - cy, cols - cx) / rad
        if np.mean((dist >= cfg.band[0]) & (dist <= cfg.band[1])) < cfg.ring_share:
            continue
        sector = ((np.arctan2(rows - cy, cols - cx) + np.pi) / (2 * np.pi) * _SECTORS).astype(int) % _SECTORS
        if len(np.unique(sector)) < cfg.sectors * _SECTORS:
            continue
        yy, xx = np.mgrid[0:h, 0:w]
        inner = np.hypot(yy - cy, xx - cx) <= cfg.inner * rad
        if proud[r0:r0 + h, c0:c0 + w][inner].mean() > cfg.inner_max:
            continue
        out.append((r0, r0 + h, c0, c0 + w))
    return out


def porthole_core(box: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """The core of porthole ``box`` (r0, r1, c0, c1) as a box (c0, r0, c1, r1) of ``front_cells.pane_boxes``:
    the disc's rows and columns holding at least half of its widest line, as a pane's core. Why the core and
    not the box: the door's own outline is a seam the splitter must still cut (the plate above it, the
    detergent drawer's bottom edge), and near the box's edge the disc is narrower than that seam's gap."""
    r0, r1, c0, c1 = box
    rad = _QUARTER * ((r1 - r0) + (c1 - c0))
    k = int(np.ceil(_CORE * rad))
    return c0 + k, r0 + k, max(c0 + k, c1 - k), max(r0 + k, r1 - k)
