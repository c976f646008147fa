"""Split a fused orthophoto of a vertical plane into front-sized cells, at seams and between handles.

Seams are thin lines darker than both sides (the shadow in the gap between two fronts), in a cell
without handles also rows brighter than both sides (the lit top edge of the drawer below), or thin gaps
in the mesh coverage; a seam must span most of the cell it splits (furniture is laid out in
guillotine cuts: a run splits into columns, a column into drawers). Handles are compact elongated
blobs whose colour differs from their surroundings (metal bars on paint). A cell still holding two
handles side by side (or stacked) is split between them at the strongest seam evidence, so a missed
seam costs nothing when both fronts have handles. Everything is in grid pixels of the orthophoto;
thresholds are in metres or brightness ratios (the orthophoto is exposure-normalised to ~1), in the
sections ``seams``, ``handles`` and ``cells`` of ``perception.heuristic`` (``image.texture_factor`` raises
seam and handle thresholds on textured planes).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy import ndimage

from ...config.heuristic import CellConfig, HandleConfig, HeuristicConfig, SeamConfig
from .constants import CONNECTIVITY, MAD_SIGMA, MIN_KERNEL, NEIGHBOURS, RGB
from .orthophoto import Orthophoto

_U8 = 128.0  # colour ~1 (the plane's mean) -> 128 in 8 bits (medianBlur needs 8 bits), room for highlights
_U8_MAX = 255  # largest 8-bit value; also the largest kernel medianBlur takes here
_ACROSS_ROW = np.ones((1, 3), np.uint8)  # a pixel and its left/right neighbours ...
_ACROSS_COL = np.ones((3, 1), np.uint8)  # ... and its upper/lower ones
_MIN_LINES = 3  # a profile of fewer usable lines has no seam
_EDGE_BAND_DIV = 3  # a cut may run through at most a third of a bar's box at each edge (its middle stays blocked)
_TWICE_PX = 2  # two bars' boxes may share this many columns at their ends (a box is blurred a px or two)
_PAIR_BAND_DIV = 3  # a cut may run through the middle third of a bar pair's box (its outer thirds stay blocked)


@dataclass
class Handle:
    """A handle blob: its pixel box (c0, r0, c1, r1) and whether it is horizontal."""

    box: tuple[int, int, int, int]
    horizontal: bool
    pixels: np.ndarray  # (N, 2) cols, rows
    knob: bool = False  # a compact knob, not a bar: it has no direction

    @property
    def center(self) -> tuple[float, float]:
        return 0.5 * (self.box[0] + self.box[2]), 0.5 * (self.box[1] + self.box[3])


@dataclass
class Cell:
    """A rectangle of grid pixels [c0, c1) x [r0, r1), the handles inside it, and how many of its
    sides are seams or handle splits (the region's outline counts as none)."""

    c0: int
    r0: int
    c1: int
    r1: int
    handles: list[Handle] = field(default_factory=list)
    cut_sides: int = 0
    seam_cuts: int = 0  # of those cuts, straight seams along the whole cell (``_dip_cut``)


@dataclass
class LearnedLines:
    """Seam evidence from learned line segments (line_evidence.py) as the cell split reads it: pixels on
    vertical and on horizontal lines that several views support, the share of a cell's length such a line
    must cover (``lines.span``), and the columns (rows) a vertical (horizontal) learned cut may not take:
    those of handles running along it. A learned seam may cross a bar handle: a handle never straddles a
    seam, so a "handle" across one is two bars joined over the gap, or a reflection."""

    vert: np.ndarray
    horiz: np.ndarray
    span: float
    blocked_c: np.ndarray
    blocked_r: np.ndarray


_THROUGH_SHARE = 0.25  # a cut with at least this share of a handle on each side runs through it


def _valleys(g: np.ndarray, axis: int, contrast: float, width_px: int) -> np.ndarray:
    """Pixels darker than both neighbours 1 to ``width_px`` px away along ``axis`` by ``contrast``."""
    out = np.zeros(g.shape, bool)
    for k in range(1, width_px + 1):
        a = np.roll(g, k, axis)
        b = np.roll(g, -k, axis)
        out |= (np.minimum(a, b) - g) > contrast
    return out


def _contrast(g: np.ndarray, axis: int, valid: np.ndarray, p: SeamConfig, texture_factor: float) -> float:
    """Valley contrast for seams: ``contrast``, raised on textured planes (wood grain makes thin
    dark lines everywhere) to ``texture_factor`` x the plane's median valley depth."""
    if not valid.any():
        return p.contrast
    depth = np.maximum(np.minimum(np.roll(g, 2, axis), np.roll(g, -2, axis)) - g, 0.0)
    return max(p.contrast, 0.5 * texture_factor * float(np.median(depth[valid])))


def _gaps(valid: np.ndarray, axis: int, width_px: int) -> np.ndarray:
    """Unseen pixels with seen pixels on both sides within ``width_px`` px along ``axis`` (thin mesh gaps)."""
    out = np.zeros(valid.shape, bool)
    for k in range(1, width_px + 1):
        a = np.roll(valid, k, axis)
        b = np.roll(valid, -k, axis)
        out |= ~valid & a & b
    return out


def seam_maps(o: Orthophoto, cfg: HeuristicConfig) -> tuple[np.ndarray, np.ndarray]:
    """Boolean maps of vertical-seam and horizontal-seam evidence."""
    p, tf = cfg.seams, cfg.image.texture_factor
    g = o.color.mean(-1)
    valid = o.n_views > 0
    # smooth along the seam direction only: a seam is a line, noise is not
    gv = cv2.blur(g, (1, p.smooth_px))
    gh = cv2.blur(g, (p.smooth_px, 1))
    vert = (_valleys(gv, 1, _contrast(gv, 1, valid, p, tf), p.width_px) & valid) | _gaps(valid, 1, p.width_px)
    horiz = (_valleys(gh, 0, _contrast(gh, 0, valid, p, tf), p.width_px) & valid) | _gaps(valid, 0, p.width_px)
    # a fused seam wobbles by a pixel (residual misregistration): tolerate it across the seam
    vert = cv2.dilate(vert.astype(np.uint8), _ACROSS_ROW).astype(bool)
    horiz = cv2.dilate(horiz.astype(np.uint8), _ACROSS_COL).astype(bool)
    return vert, horiz


def off_background(o: Orthophoto, h: HandleConfig) -> np.ndarray:
    """Colour distance of every pixel from its local background (median over ``background_win``)."""
    return off_local(o.color, o.n_views > 0, o.res, h)


def off_local(color: np.ndarray, valid: np.ndarray, res: float, h: HandleConfig) -> np.ndarray:
    """Colour distance of every pixel of ``color`` (an orthophoto or a window of one, ``res`` m per px) from
    its local background: the median over ``background_win`` of the ``valid`` pixels' colours, the array
    mirrored beyond its border."""
    if not valid.any():
        return np.zeros(valid.shape, np.float32)
    c = np.clip(color * _U8, 0, _U8_MAX).astype(np.uint8)
    c[~valid] = np.median(c[valid], axis=0).astype(np.uint8)  # unseen pixels must not look like blobs
    k = min(max(MIN_KERNEL, int(h.background_win / res) | 1), _U8_MAX)
    # mirrored, not replicated, beyond the orthophoto's border: medianBlur repeats the last row, so a dark
    # band along a wall cabinet's bottom edge filled half the window of a flap's handle 5 cm above it
    # and the bar matched its "background"
    r = k // 2
    bg = cv2.medianBlur(cv2.copyMakeBorder(c, r, r, r, r, cv2.BORDER_REFLECT_101), k)[r:-r, r:-r]
    return np.linalg.norm(c.astype(np.float32) - bg.astype(np.float32), axis=-1) / _U8


def off_threshold(diff: np.ndarray, valid: np.ndarray, cfg: HeuristicConfig) -> float:
    """Colour distance above which a pixel is off its background: ``handles.contrast``, raised on
    textured planes (wood grain deviates everywhere) to ``image.texture_factor`` x the plane's median."""
    if not valid.any():
        return cfg.handles.contrast
    return max(cfg.handles.contrast, cfg.image.texture_factor * float(np.median(diff[valid])))


def _is_bar(w: int, h: int, area: int, res: float, p: HandleConfig) -> bool:
    """A box ``w`` x ``h`` px holding ``area`` px is a bar handle's: its sides within ``p.length`` and
    ``p.thickness``, ``p.aspect`` times longer than thick, ``p.min_fill`` of it filled."""
    long_, short = max(w, h) * res, min(w, h) * res
    return (p.length[0] <= long_ <= p.length[1] and p.thickness[0] <= short <= p.thickness[1]
            and max(w, h) >= p.aspect * min(w, h) and area >= p.min_fill * w * h)


def _candidates(lab: np.ndarray, stats: np.ndarray, n: int, mesh_bars: np.ndarray | None, res: float,
                p: HandleConfig, bars_only: bool):  # noqa: ANN202 - a generator of plain tuples
    """Each blob of ``lab`` as (label, x, y, w, h, area, is_bar, is_knob). A blob that is neither, when
    ``mesh_bars`` is given, yields instead each piece of it that ``mesh_bars`` (the mesh's protrusions)
    holds on its own and that is a bar, relabelled in ``lab`` with a new label. Why: a lip standing proud
    along a drawer's top edge is a plain bar in the mesh, but the colour above it (its top face, dark)
    and the protrusion the local surface reads along the proud drawer's side joined it into a blob too
    thick for a handle (washing machines' detergent drawers: none had a handle)."""
    nxt = n
    for j in range(1, n):
        x, y, w, h, area = (int(v) for v in stats[j])
        bar = _is_bar(w, h, area, res, p)
        knob = not bar and not bars_only and p.knobs and _is_knob(w, h, area, res, p)
        if bar or knob or mesh_bars is None:
            yield j, x, y, w, h, area, bar, knob
            continue
        part = (mesh_bars[y:y + h, x:x + w] & (lab[y:y + h, x:x + w] == j)).astype(np.uint8)
        m, sub, st, _ = cv2.connectedComponentsWithStats(part, connectivity=CONNECTIVITY)
        for k in range(1, m):
            a, b, ww, hh, ar = (int(v) for v in st[k])
            if _is_bar(ww, hh, ar, res, p):
                lab[y:y + h, x:x + w][sub == k] = nxt
                yield nxt, x + a, y + b, ww, hh, ar, True, False
                nxt += 1


def find_handles(o: Orthophoto, coverage: np.ndarray, cfg: HeuristicConfig, diff: np.ndarray | None = None,
                 protrusion: np.ndarray | None = None, outline: np.ndarray | None = None,
                 bars_only: bool = False, lone: list[Handle] | None = None) -> list[Handle]:
    """Compact elongated blobs whose colour differs from the local background (see module docstring),
    and with ``handles.knobs`` compact round ones (``_is_knob``) unless ``bars_only``; the knobs left out
    for standing alone (``knobs_in_patterns``) are appended to ``lone`` when given.
    Colour blobs keep ``handles.outline_margin`` inside ``coverage`` (colour beside a scanning shadow is
    misregistered); a handle must lie inside ``outline`` (coverage with handle shadows filled; default
    ``coverage``)."""
    p = cfg.handles
    valid = o.n_views > 0
    if valid.sum() < p.min_seen_px:
        return []
    diff = off_background(o, p) if diff is None else diff
    thr = off_threshold(diff, valid, cfg)
    # the plane's own outline (a worktop edge's shadow, the floor line) is no handle: keep 2 cm away
    edge = max(1, int(round(p.outline_margin / o.res)))
    inner = cv2.erode(coverage.astype(np.uint8), np.ones((2 * edge + 1, 2 * edge + 1), np.uint8)).astype(bool)
    colour = ((diff > thr) & valid & inner).astype(np.uint8)
    # a handle that is in the mesh: its footprint in front of the plane
    bar = np.zeros_like(colour) if protrusion is None else protrusion.astype(np.uint8)
    blob = colour | bar
    # strips (shadow lines along an edge, seams) would join handles: remove them
    L = int(p.strip_length / o.res) + 1
    strips = cv2.morphologyEx(blob, cv2.MORPH_OPEN, np.ones((1, L), np.uint8)) | \
        cv2.morphologyEx(blob, cv2.MORPH_OPEN, np.ones((L, 1), np.uint8))
    keep = 1 - cv2.dilate(strips, NEIGHBOURS)
    # the opening cuts 1-2 px grain bridges in the colour; a bar in the mesh is no grain and, 3-4 px wide
    # at 4 mm, would fall apart under it
    blob = cv2.morphologyEx(colour & keep, cv2.MORPH_OPEN, NEIGHBOURS) | (bar & keep)
    g = max(MIN_KERNEL, int(p.join_gap / o.res) | 1)  # a bar broken by a highlight is one handle
    blob = cv2.morphologyEx(blob, cv2.MORPH_CLOSE, np.ones((1, g), np.uint8))
    n, lab, stats, _ = cv2.connectedComponentsWithStats(blob, connectivity=CONNECTIVITY)
    mesh_bars = bar & keep if p.mesh_bar_parts else None
    out = []
    seams = hidden = None
    # the plane's median view count, read only by few_views (and None with min_seen_px 0 on an unseen plane)
    plane_views = float(np.median(o.n_views[valid])) if p.few_views > 0 and valid.any() else None
    for j, x, y, w, h, area, bar, knob in _candidates(lab, stats, n, mesh_bars, o.res, p, bars_only):
        if not (bar or knob):
            continue
        if p.seam_share > 0:
            seams = _long_seams(o, cfg, L) if seams is None else seams
            if (seams[y:y + h, x:x + w][lab[y:y + h, x:x + w] == j]).mean() >= p.seam_share:
                continue
        # a handle sits on the front: mesh coverage around it on both sides across its length
        pad = max(2, int(p.side_band / o.res))
        r0, r1, c0, c1 = max(0, y - pad), min(lab.shape[0], y + h + pad), max(0, x - pad), min(lab.shape[1], x + w + pad)
        ref = coverage if outline is None else outline
        if ref[r0:r1, c0:c1].mean() < p.around_cover:
            continue
        if p.side_cover > 0 and min(_side_cover(ref, (x, y, w, h), pad)) < p.side_cover:
            continue
        if p.hidden_side > 0 and not bars_only:
            hidden = coverage.astype(bool) & ~valid if hidden is None else hidden
            depth = max(pad, int(round(p.hidden_depth / o.res)))
            if _at_hidden_edge(hidden, protrusion, lab[y:y + h, x:x + w] == j, (x, y, w, h), pad, p, depth):
                continue
        rows, cols = np.nonzero(lab[y:y + h, x:x + w] == j)
        if plane_views is not None and not bars_only and _few_views(o.n_views, rows + y, cols + x, protrusion, p, plane_views):
            continue
        out.append(Handle((int(x), int(y), int(x + w), int(y + h)), bool(w >= h), np.stack([cols + x, rows + y], 1), knob))
    if p.knob_pair > 0:
        kept = knobs_in_patterns(out, p.knob_pair / o.res, p.knob_pair_size, p.knob_pair_reach / o.res,
                                 p.knob_panel_gap / o.res)
        if lone is not None:
            ids = {id(h) for h in kept}
            lone += [h for h in out if id(h) not in ids]
        out = kept
    if protrusion is not None and not bars_only:
        out = bars_outrank_colour(out, protrusion, p.bar_plane_min, p.bar_share, p.bar_reach / o.res,
                                  p.bar_row / o.res, p.bar_row_gap / o.res)
    return out


_PANEL_KNOBS = 3  # a door pair has two knobs side by side; a control panel's row has more


def knobs_in_patterns(handles: list[Handle], tol_px: float, size_ratio: float, reach_px: float = np.inf,
                      panel_px: float = 0.0) -> list[Handle]:
    """``handles`` less the knobs that no other knob of a like size (sides within ``size_ratio`` of each
    other's) lines up with: centres within ``tol_px`` in the row or in the column, at most ``reach_px``
    apart. Knobs in a row of three or more whose neighbours are at most ``panel_px`` apart go too.

    Why: furniture repeats its knobs (a column of drawers, the two doors of a pair, a row of sideboard
    fronts), while a compact blob on a real front (a reflection, a sticker, a screw head the scan caught)
    passes the knob's size and fill tests alone: on RedKitchen every such blob stood alone on its plane
    or off the others' rows and columns. A row of knobs closer than any front is wide is an appliance's
    control panel: its knobs open nothing, and cutting between them halved the oven door below."""
    knobs = [h for h in handles if h.knob]
    if not knobs:
        return handles
    box = np.array([h.box for h in knobs], float)
    cx, cy = (box[:, 0] + box[:, 2]) / 2, (box[:, 1] + box[:, 3]) / 2
    w, h = box[:, 2] - box[:, 0], box[:, 3] - box[:, 1]
    like = (np.maximum(w[:, None], w[None]) <= size_ratio * np.minimum(w[:, None], w[None])) & \
        (np.maximum(h[:, None], h[None]) <= size_ratio * np.minimum(h[:, None], h[None]))
    dx, dy = np.abs(cx[:, None] - cx[None]), np.abs(cy[:, None] - cy[None])
    in_row = like & (dy <= tol_px)
    panel = np.zeros(len(knobs), bool)
    if panel_px > 0:
        for i in range(len(knobs)):
            row = np.flatnonzero(in_row[i])  # i and its like knobs in its row, left to right
            xs = cx[row]
            order = np.argsort(xs)
            runs = np.split(row[order], np.flatnonzero(np.diff(xs[order]) > panel_px) + 1)
            panel[i] = any(i in r and len(r) >= _PANEL_KNOBS for r in runs)
    pair = like & ((dx <= tol_px) | (dy <= tol_px)) & (np.hypot(dx, dy) <= reach_px) & ~panel[:, None] & ~panel[None]
    np.fill_diagonal(pair, False)
    kept = {id(k) for k, ok in zip(knobs, pair.any(1)) if ok}
    return [h for h in handles if not h.knob or id(h) in kept]


def _at_hidden_edge(hidden: np.ndarray, protrusion: np.ndarray | None, mine: np.ndarray,
                    box: tuple[int, int, int, int], pad: int, p: HandleConfig, depth_px: int = 0) -> bool:
    """Whether a blob (``mine``: its pixels in its ``box`` x, y, w, h) is colour only (under ``p.bar_share`` of it
    on ``protrusion``) and has, along a long side, ``p.hidden_side`` or more of the ``pad``-wide band ``hidden``:
    on the plane's surface (its coverage) but seen by no view; and as much of the ``pad``-wide band on that
    side that ends ``depth_px`` from the blob (``handles.hidden_depth``; 0 or ``pad``: the first band only).

    Why: there the plane is hidden from every view by something in front of it (a chair, a box, the next
    piece), and the colour along that edge is the edge of whatever hides it, or the plane's own edge lit or
    shaded: the sides and backs of pieces standing free became doors at such blobs (free-standing tuning,
    laser scans: a sideboard's back and side, a box's side, a turned piece's back). A handle's scanning
    shadow is no such band: the scan lacks the surface there, so it is not ``coverage``; and a handle the
    scan holds stands out of the plane. What a real handle hides beside it from oblique views, or what a
    worktop's overhang hides above a top handle, is a strip a few cm wide; an occluder hides more: on
    RedKitchen a chair hid a 25 cm patch of a door, whose edge became a second handle and cut the door in
    two, while the left run's handles have up to about 5 cm of unseen surface beside them."""
    x, y, w, h = box
    if protrusion is not None and float(protrusion[y:y + h, x:x + w][mine].mean()) >= p.bar_share:
        return False
    near = _side_cover(hidden, box, pad)
    g = depth_px - pad
    far = _side_cover(hidden, box, pad, g) if g > 0 else near
    return any(a >= p.hidden_side and b >= p.hidden_side for a, b in zip(near, far))


def _few_views(n_views: np.ndarray, rows: np.ndarray, cols: np.ndarray, protrusion: np.ndarray | None,
               p: HandleConfig, plane_views: float) -> bool:
    """Whether a blob (its pixels at ``rows``, ``cols``) is colour only (under ``p.bar_share`` of it on
    ``protrusion``) and seen by a median number of views under ``p.few_views`` times ``plane_views`` (the
    median over the plane's seen pixels). Why: such a blob lies on the shore of what the views see, where
    the colour is that of one or two grazing views, misregistered (RedKitchen at 100k faces: the bottom
    edge of a base unit seen past the island by a median of 2 views, against 17-27 on its handles, became
    a handle and cut two doors apart along their handles); a ratio, so it holds at any number of frames."""
    if protrusion is not None and float(protrusion[rows, cols].mean()) >= p.bar_share:
        return False
    return float(np.median(n_views[rows, cols])) < p.few_views * plane_views


def stand_out(handles: Sequence[Handle], bars: np.ndarray, share: float) -> list[bool]:
    """Per handle: at least ``share`` of its pixels lie on ``bars`` (the surface in front of the plane), so the
    scan holds it as a bar."""
    return [float(bars[h.pixels[:, 1], h.pixels[:, 0]].mean()) >= share for h in handles]


def bars_outrank_colour(handles: list[Handle], bars: np.ndarray, min_bars: int, share: float,
                        reach_px: float = 0.0, row_px: float = 0.0, row_gap_px: float = 0.0) -> list[Handle]:
    """``handles`` less the colour-only ones when at least ``min_bars`` of them (0: never) stand out of the
    scan: ``share`` or more of their pixels on ``bars`` (the surface in front of the plane). With
    ``reach_px`` > 0 only a colour-only handle whose box lies within that many pixels of a bar's box goes.

    Why: a plane whose handles the scan holds as bars shows its handles there; a raised panel's bevels
    and the shading along its frame are straight colour lines of a bar's size beside them (a
    scene-synthesizer door's panel edge under its bar, the worktop's shadow along a drawer's top), and
    every one read as a handle cut its door between it and the door's real handle. A handle the views see
    but the scan does not hold is kept on planes where no handles stand out (a decimated or a real scan).
    With ``row_px`` > 0 a colour-only bar in line with a bar the scan holds (``in_line_with``: the next front's
    handle in the same row or column) stays: a scan holds some bars of a run and loses others (a dark front's
    pale bars standing over a surface the sensor missed), while a bevel or a shadow line runs beside a bar."""
    if min_bars <= 0:
        return handles
    on_bar = stand_out(handles, bars, share)
    if sum(on_bar) < min_bars:
        return handles
    if row_px > 0:
        held = [h for h, b in zip(handles, on_bar) if b]
        on_bar = [b or in_line_with(h, held, row_px, row_gap_px) for h, b in zip(handles, on_bar)]
    if reach_px <= 0:
        return [h for h, b in zip(handles, on_bar) if b]
    boxes = np.array([h.box for h, b in zip(handles, on_bar) if b], float)

    def near_bar(h: Handle) -> bool:
        dx = np.maximum(0.0, np.maximum(boxes[:, 0] - h.box[2], h.box[0] - boxes[:, 2]))
        dy = np.maximum(0.0, np.maximum(boxes[:, 1] - h.box[3], h.box[1] - boxes[:, 3]))
        return bool((np.hypot(dx, dy) <= reach_px).any())

    return [h for h, b in zip(handles, on_bar) if b or not near_bar(h)]


def in_line_with(h: Handle, bars: Sequence[Handle], across_px: float, gap_px: float, length_ratio: float = 2.0) -> bool:
    """Whether bar ``h`` lies in line with one of ``bars``: both bars (no knobs) running the same way, their centre
    lines within ``across_px`` across, their boxes at least ``gap_px`` apart along the line and neither more than
    ``length_ratio`` times the other's length: the handles of a row of drawers, of a column of doors."""
    if h.knob:
        return False
    ax = 0 if h.horizontal else 1  # the axis the bar runs along (columns for a horizontal bar)
    lo, hi = h.box[ax], h.box[ax + 2]
    mid = 0.5 * (h.box[1 - ax] + h.box[3 - ax])
    for b in bars:
        if b.knob or b.horizontal != h.horizontal or b is h:
            continue
        blo, bhi = b.box[ax], b.box[ax + 2]
        if (abs(0.5 * (b.box[1 - ax] + b.box[3 - ax]) - mid) <= across_px and max(blo - hi, lo - bhi) >= gap_px
                and max(hi - lo, bhi - blo) <= length_ratio * max(min(hi - lo, bhi - blo), 1)):
            return True
    return False


def _is_knob(w: int, h: int, area: int, res: float, p: HandleConfig) -> bool:
    """A blob of ``w`` x ``h`` px holding ``area`` px is a knob: both sides within ``knob_size`` (m), at most
    ``knob_aspect`` long for its width, filling ``knob_min_fill`` of its box (a disc fills pi / 4)."""
    return bool(p.knob_size[0] <= min(w, h) * res and max(w, h) * res <= p.knob_size[1]
                and max(w, h) <= p.knob_aspect * min(w, h) and area >= p.knob_min_fill * w * h)


def _long_seams(o: Orthophoto, cfg: HeuristicConfig, length_px: int) -> np.ndarray:
    """Pixels on straight seam evidence (``seam_maps``) running at least ``length_px`` (longer than any handle)
    along a column or a row.

    Why: a seam between two fronts fused from views a pixel or two apart is a dark line 3-5 px wide, and
    where only part of it is dark enough to pass the handle contrast, that part is a 0.25 m x 16 mm dark bar
    (clean kitchen 101: one on the gap between two wall-cabinet doors split the left door at a false handle).
    The seam evidence runs on along the whole seam where the handle contrast breaks off."""
    vert, horiz = seam_maps(o, cfg)
    lv = cv2.morphologyEx(vert.astype(np.uint8), cv2.MORPH_OPEN, np.ones((length_px, 1), np.uint8))
    lh = cv2.morphologyEx(horiz.astype(np.uint8), cv2.MORPH_OPEN, np.ones((1, length_px), np.uint8))
    return (lv | lh).astype(bool)


def _side_cover(ref: np.ndarray, box: tuple[int, int, int, int], pad: int, gap: int = 0) -> tuple[float, float]:
    """Share of the ``pad``-wide bands along both long sides of ``box`` (x, y, w, h), ``gap`` px off it, that
    ``ref`` covers; band pixels beyond the grid count as uncovered (the plane ends there)."""
    x, y, w, h = box
    H, W = ref.shape

    def band(a: int, b: int, n: int) -> slice:
        return slice(min(max(a, 0), n), min(max(b, 0), n))

    if w >= h:  # horizontal: above and below
        bands = [ref[band(y - gap - pad, y - gap, H), band(x, x + w, W)],
                 ref[band(y + h + gap, y + h + gap + pad, H), band(x, x + w, W)]]
        full = pad * w
    else:  # vertical: left and right
        bands = [ref[band(y, y + h, H), band(x - gap - pad, x - gap, W)],
                 ref[band(y, y + h, H), band(x + w + gap, x + w + gap + pad, W)]]
        full = pad * h
    return float(bands[0].sum()) / full, float(bands[1].sum()) / full


def split_cells(o: Orthophoto, coverage: np.ndarray, handles: list[Handle], cfg: HeuristicConfig,
                lines: tuple[np.ndarray, np.ndarray] | None = None, lone: list[Handle] = (),
                panes: np.ndarray | None = None, barred: Sequence[tuple[int, int, int, int]] = ()) -> list[Cell]:
    """Guillotine partition of the plane's covered area at spanning seams, then between handle pairs.
    ``lines``: pixels on vertical and on horizontal lines that learned line segments of several views
    support (line_evidence.py; ``perception.heuristic.lines``), a seam where the brightness shows none.
    ``lone``: knobs not taken as handles; with ``cells.lone_knobs_block`` no cut runs through them either
    (a chest's wide top drawer has one knob in its middle, over the seam between the two drawers of each
    row below; the seam's line ran on up through the knob and halved the top drawer).
    ``panes``: the plane's glass panes (``image_fronts.framed_panes``); with ``cells.pane_margin`` > 0 no cut
    runs through a pane or within that margin of it. ``barred``: more boxes (c0, r0, c1, r1; grid px, end
    exclusive) no cut runs through, as it runs through no pane: porthole doors' cores."""
    rows, cols = np.nonzero(coverage)
    if not len(rows):
        return []
    p, cells_cfg = cfg.seams, cfg.cells
    vert, horiz = seam_maps(o, cfg)
    root = Cell(int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1)
    min_px = max(2, int(cells_cfg.min_side / o.res))
    blocked_c = np.zeros(coverage.shape[1], bool)  # no cut runs through a handle
    blocked_r = np.zeros(coverage.shape[0], bool)
    pull_px = int(round(cells_cfg.edge_pull / o.res))
    pair_px = int(np.ceil(2 * cfg.handles.thickness[0] / o.res)) if cells_cfg.bar_pairs else 0
    for h in list(handles) + (list(lone) if cells_cfg.lone_knobs_block else []):
        blocked_c[h.box[0]:h.box[2]] = True
        if _bar_pair(h, pair_px):  # its middle may hold the seam where two doors meet
            w = h.box[2] - h.box[0]
            blocked_c[h.box[0] + w // _PAIR_BAND_DIV:h.box[2] - w // _PAIR_BAND_DIV] = False
        # a horizontal bar's top rows may hold the seam it hangs from (its box is blurred over it)
        e = min(pull_px, (h.box[3] - h.box[1]) // _EDGE_BAND_DIV) if h.horizontal and not h.knob else 0
        blocked_r[h.box[1] + e:h.box[3]] = True
    col = np.where((o.n_views > 0)[..., None], o.color, np.nan)  # unseen pixels carry no colour
    g = col.mean(-1)
    gs, cols = (g, g), (col, col)  # read by profiles over columns (vertical seams), over rows (horizontal ones)
    if cells_cfg.seams_past_handles:
        on_handle = handle_pixels(list(handles) + list(lone), coverage.shape)
        cols = (fill_along(col, on_handle, 0), fill_along(col, on_handle, 1))
        gs = (cols[0].mean(-1), cols[1].mean(-1))  # the blend is linear and a pixel is NaN in every channel or none
    learned = None
    if lines is not None:
        along_c = np.zeros(coverage.shape[1], bool)  # columns of vertical handles, rows of horizontal ones
        along_r = np.zeros(coverage.shape[0], bool)
        for h in handles:
            if h.horizontal:
                along_r[h.box[1]:h.box[3]] = True
            else:
                along_c[h.box[0]:h.box[2]] = True
        learned = LearnedLines(lines[0], lines[1], cfg.lines.span, along_c, along_r)
    boxes = (pane_boxes(panes, int(round(cells_cfg.pane_margin / o.res)))
             if panes is not None and cells_cfg.pane_margin > 0 else []) + list(barred)
    cells = _split(root, vert, horiz, coverage, p, cells_cfg, min_px, 0, blocked_c, blocked_r, handles, gs, cols, learned,
                   int(cells_cfg.edge_strip / o.res), pull_px, boxes)
    if pair_px:
        handles = _split_bar_pairs(handles, cells, pair_px)
    for c in cells:
        c.handles = [h for h in handles if c.c0 <= h.center[0] < c.c1 and c.r0 <= h.center[1] < c.r1]
    held = {id(h) for c in cells for h in c.handles}
    for h in handles:  # centred on a learned cut through it (the cut line is in no cell): the nearest cell
        if id(h) not in held and cells:
            x, y = h.center
            min(cells, key=lambda c: np.hypot(max(c.c0 - x, 0.0, x - c.c1), max(c.r0 - y, 0.0, y - c.r1))).handles.append(h)
    out: list[Cell] = []
    for c in cells:
        pitched = _pitch_split(c, gs[1], coverage, min_px, p, cells_cfg.pitch_tol) if cells_cfg.pitch_tol > 0 else None
        for piece in pitched or _split_handles(c, vert, horiz, coverage, min_px, gs, p, learned, boxes):
            out += _split_at_pulls(piece, gs[1], coverage, min_px, pull_px, p, boxes)
    if cells_cfg.sliver_max > 0:
        out = merge_slivers(out, int(cells_cfg.sliver_max / o.res), cells_cfg.sliver_ratio)
    return out


def _bar_pair(h: Handle, pair_px: int) -> bool:
    """Whether ``h`` is a vertical bar at least ``pair_px`` wide (two bars' thickness; 0: never)."""
    return pair_px > 0 and not h.horizontal and not h.knob and h.box[2] - h.box[0] >= pair_px


def _split_bar_pairs(handles: list[Handle], cells: list[Cell], pair_px: int) -> list[Handle]:
    """Each wide vertical bar (``_bar_pair``) that a cell's side runs through, between its rows, as two
    handles: its pixels either side of that column. Why: where two doors meet, their bars either side of the
    seam fuse into one blob (in the colour and in the mesh at 1 cm); once the seam is cut through the blob's
    middle, each door holds its own bar."""
    out = []
    for h in handles:
        cut = None
        if _bar_pair(h, pair_px):
            w = h.box[2] - h.box[0]
            lo, hi = h.box[0] + w // _PAIR_BAND_DIV, h.box[2] - w // _PAIR_BAND_DIV
            y = h.center[1]
            cut = next((c.c1 for c in cells if lo <= c.c1 < hi and c.r0 <= y < c.r1), None)
        if cut is None:
            out.append(h)
            continue
        out += [part for part in (_part_handle(h, h.pixels[:, 0] < cut), _part_handle(h, h.pixels[:, 0] > cut))
                if part is not None]
    return out


def handle_pixels(handles: list[Handle], shape: tuple[int, int], grow: int = 1) -> np.ndarray:
    """Bool image of the handles' pixels, grown by ``grow`` px (a blob's rim is blurred into the front)."""
    m = np.zeros(shape, np.uint8)
    for h in handles:
        m[h.pixels[:, 1], h.pixels[:, 0]] = 1
    if grow > 0 and m.any():
        m = cv2.dilate(m, np.ones((2 * grow + 1, 2 * grow + 1), np.uint8))
    return m.astype(bool)


def fill_along(g: np.ndarray, mask: np.ndarray, axis: int) -> np.ndarray:
    """``g`` with its ``mask`` pixels replaced, line by line along ``axis`` (1: rows, 0: columns), by the
    linear blend of the nearest unmasked finite values before and after them on that line (the one there
    is where the line ends or holds only NaN on one side). Why: a seam continues straight through what
    hides it, so read along its own direction it is filled in, where an isotropic fill would smear the
    front over it; a handle stands in a hole of the plane's surface (it is not on the plane), so its
    nearest neighbours are often unseen."""
    if not mask.any():
        return g
    if axis == 0:
        return np.swapaxes(fill_along(np.swapaxes(g, 0, 1), mask.T, 1), 0, 1)
    n = g.shape[1]
    ar = np.arange(n)[None, :]
    bad = np.isnan(g) if g.ndim == 2 else np.isnan(g).any(axis=tuple(range(2, g.ndim)))
    src = mask | bad
    left = np.maximum.accumulate(np.where(src, -1, ar), axis=1)
    right = np.minimum.accumulate(np.where(src, n, ar)[:, ::-1], axis=1)[:, ::-1]
    rows = np.arange(g.shape[0])[:, None]
    tail = (slice(None), slice(None)) + (None,) * (g.ndim - 2)  # colour channels ride along
    lo, hi = left >= 0, right < n
    gl = np.where(lo[tail], g[rows, np.clip(left, 0, n - 1)], np.nan)
    gr = np.where(hi[tail], g[rows, np.clip(right, 0, n - 1)], np.nan)
    w = ((ar - left) / np.maximum(right - left, 1))[tail]
    fill = np.where(np.isnan(gl), gr, np.where(np.isnan(gr), gl, gl + w * (gr - gl)))
    return np.where(mask[tail], fill, g)


def _part_handle(h: Handle, keep: np.ndarray) -> Handle | None:
    """The pixels of ``h`` that ``keep`` selects, as a handle of their own (None: none)."""
    px = h.pixels[keep]
    if not len(px):
        return None
    box = (int(px[:, 0].min()), int(px[:, 1].min()), int(px[:, 0].max()) + 1, int(px[:, 1].max()) + 1)
    return Handle(box, h.horizontal, px, h.knob)


def merge_slivers(cells: list[Cell], max_px: int, ratio: float) -> list[Cell]:
    """Cut each sliver (a cell at most ``max_px`` wide between two cells of its rows, each at least ``ratio``
    times wider) down its middle and give each half, with its part of the sliver's handles, to its
    neighbour. Where two doors meet, bar handles either side of the seam fuse into one blob, and no cut runs
    through a handle, so the guillotine cut on both of its sides and left the stile between them as a cell;
    the stile's middle is the seam (a dark line there is no help: the bars are dark lines too)."""
    out = list(cells)
    gone: set[int] = set()
    for s in sorted(cells, key=lambda c: c.c1 - c.c0):
        w = s.c1 - s.c0
        if w > max_px or id(s) in gone:
            continue

        def beside(c: Cell) -> bool:
            return (c is not s and id(c) not in gone and abs(c.r0 - s.r0) <= 2 and abs(c.r1 - s.r1) <= 2
                    and c.c1 - c.c0 >= ratio * w)

        left = [c for c in out if beside(c) and abs(c.c1 + 1 - s.c0) <= 1]
        right = [c for c in out if beside(c) and abs(s.c1 + 1 - c.c0) <= 1]
        if len(left) != 1 or len(right) != 1:
            continue
        a, b = left[0], right[0]
        cut = (s.c0 + s.c1) // 2
        for h in s.handles:
            for side, keep in ((a, h.pixels[:, 0] < cut), (b, h.pixels[:, 0] > cut)):
                part = _part_handle(h, keep)
                if part is not None:
                    side.handles.append(part)
        a.c1, b.c0 = cut, cut + 1
        gone.add(id(s))
    return [c for c in out if id(c) not in gone]


def _profile(ev: np.ndarray, cov: np.ndarray, axis: int, chunks: int = 1) -> np.ndarray:
    """Fraction of covered pixels along ``axis`` that carry seam evidence, per line across it; with
    ``chunks`` > 1 the smallest such fraction over that many equal pieces of the line (a seam runs the
    whole length; a row of handles or a patch of noise does not)."""
    if chunks > 1 and ev.shape[axis] >= _MIN_LINES * chunks:
        parts = zip(np.array_split(ev, chunks, axis), np.array_split(cov, chunks, axis))
        return np.min([_profile(e, c, axis) for e, c in parts], axis=0)
    n = cov.sum(axis)
    return np.where(n > 0, (ev & cov).sum(axis) / np.maximum(n, 1), 0.0)


def _best_cut(ev: np.ndarray, cov: np.ndarray, axis: int, min_px: int, p: SeamConfig,
              blocked: np.ndarray) -> tuple[int, float]:
    """Best split line (index in the cell, prominence) keeping ``min_px`` on each side; lines covering
    less than ``span`` of the cell (or half of it in any of ``span_chunks`` pieces) score 0."""
    prof = _profile(ev, cov, axis)
    if len(prof) <= 2 * min_px:
        return -1, 0.0
    prom = prof - ndimage.median_filter(prof, size=2 * min_px + 1, mode="nearest")
    prom = np.where((prof >= p.span) & (_profile(ev, cov, axis, p.span_chunks) >= 0.5 * p.span) & ~blocked, prom, 0.0)
    inner = prom[min_px:len(prof) - min_px]
    i = int(np.argmax(inner))
    return i + min_px, float(inner[i])


def _dip_scores(g: np.ndarray, cov: np.ndarray, axis: int, min_px: int, p: SeamConfig) -> np.ndarray:
    """Per line across ``axis``: how far its median brightness dips below the lines beside it (within
    ``min_px``), in noise units. A seam is a straight dark line along the whole cell, so the median over
    the line dips, while wood grain, noise and reflections wander and average out (boolean valley counts
    saturate on strongly grained fronts). Lines covered less than ``min_line_cover`` score 0."""
    cov = cov & np.isfinite(g)
    n = cov.sum(axis)
    if not n.any():
        return np.zeros(len(n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN lines are handled below
        prof = np.nanmedian(np.where(cov, g, np.nan), axis)
    ok = (n >= p.min_line_cover * n.max()) & np.isfinite(prof)
    if ok.sum() < _MIN_LINES:
        return np.zeros(len(n))
    prof = np.where(ok, prof, np.median(prof[ok]))
    dip = ndimage.median_filter(prof, size=2 * min_px + 1, mode="nearest") - prof
    noise = max(MAD_SIGMA * float(np.median(np.abs(dip[ok] - np.median(dip[ok])))), p.noise_floor)
    whole = _dips_in_every_piece(g, cov, axis, min_px, p) if p.piece_sides > 0 else True
    return np.where(ok & (dip >= p.contrast) & whole, dip / noise, 0.0)


def _dips_in_every_piece(g: np.ndarray, cov: np.ndarray, axis: int, min_px: int, p: SeamConfig) -> np.ndarray:
    """Per line across ``axis``: whether its median brightness dips by ``piece_contrast`` below the lines
    beside it in every piece of its length (pieces ``piece_sides`` x ``min_px`` long; a piece where the line is
    covered less than ``min_line_cover`` of its best-covered line there is not judged).

    Why: a line's median over the whole cell dips as soon as more than half of it is dark, so a seam
    between stacked drawers that spans 60 % of a run cut the door beside them, whose face shows no step
    there. A seam runs along the whole cell; a line dark in one piece and plain in the next is none."""
    length = cov.shape[axis]
    n_pieces = max(1, length // max(1, p.piece_sides * min_px))
    out = np.ones(cov.shape[1 - axis], bool)
    if n_pieces < 2:
        return out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN lines of a piece are not judged
        for gp, cp in zip(np.array_split(g, n_pieces, axis), np.array_split(cov, n_pieces, axis)):
            n = cp.sum(axis)
            if not n.any():
                continue
            prof = np.nanmedian(np.where(cp, gp, np.nan), axis)
            ok = (n >= p.min_line_cover * n.max()) & np.isfinite(prof)
            if ok.sum() < _MIN_LINES:
                continue
            prof = np.where(ok, prof, np.median(prof[ok]))
            dip = ndimage.median_filter(prof, size=2 * min_px + 1, mode="nearest") - prof
            out &= ~ok | (dip >= p.piece_contrast)
    return out


def _step_scores(c: np.ndarray, cov: np.ndarray, axis: int, min_px: int, p: SeamConfig) -> np.ndarray:
    """Per line across ``axis``: the colour step between the ``k`` lines before and after it (median
    colour per line, k = min_px / 2), where it is at least ``step_contrast``, in noise units. A front of
    another colour than what surrounds it (a brown door leaf in a pale wall) has no dark seam, only a
    step along its whole edge."""
    seen = cov & np.isfinite(c[..., 0])
    n = seen.sum(axis)
    if not n.any():
        return np.zeros(len(n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        prof = np.stack([np.nanmedian(np.where(seen, c[..., j], np.nan), axis) for j in range(RGB)], 1)
    ok = (n >= p.min_line_cover * n.max()) & np.isfinite(prof[:, 0])
    if ok.sum() < _MIN_LINES:
        return np.zeros(len(n))
    idx = np.arange(len(n))
    prof = np.stack([np.interp(idx, idx[ok], prof[ok, j]) for j in range(RGB)], 1)
    k = max(2, min_px // 2)
    cs = np.vstack([np.zeros((1, RGB)), np.cumsum(prof, 0)])
    lo = np.clip(idx - k, 0, None)
    hi = np.clip(idx + 1 + k, None, len(n))
    before = (cs[idx] - cs[lo]) / np.maximum(idx - lo, 1)[:, None]
    after = (cs[hi] - cs[idx + 1]) / np.maximum(hi - idx - 1, 1)[:, None]
    step = np.linalg.norm(after - before, axis=1)
    step[(idx - lo < k) | (hi - idx - 1 < k)] = 0.0
    noise = max(MAD_SIGMA * float(np.median(np.abs(step[ok] - np.median(step[ok])))), p.noise_floor)
    return np.where(ok & (step >= p.step_contrast), step / noise, 0.0)


def _dip_cut(g: np.ndarray, cov: np.ndarray, axis: int, min_px: int, p: SeamConfig,
             blocked: np.ndarray, scores: Callable = _dip_scores) -> tuple[int, float]:
    """Best split line by ``scores`` (``_dip_scores`` or ``_step_scores``; index in the cell, score),
    keeping ``min_px`` on each side and off ``blocked`` lines."""
    if cov.shape[1 - axis] <= 2 * min_px:
        return -1, 0.0
    z = np.where(blocked, 0.0, scores(g, cov, axis, min_px, p))
    inner = z[min_px:len(z) - min_px]
    i = int(np.argmax(inner))
    return i + min_px, float(inner[i])


def _outline_cut(cov: np.ndarray, axis: int, min_px: int, blocked: np.ndarray) -> tuple[int, float]:
    """Where the cell's covered extent across lines jumps (index in the cell, jump as a share of the
    cell's extent along ``axis``): the corner of an L-shaped outline, a tall unit beside a base run.
    The jump is between the medians of the ``min_px`` lines on either side, so a hole narrower than
    half of that (a handle's scanning shadow, a ragged TSDF edge) is not a corner; it is placed at the
    steepest single-line change near it. Both sides keep ``min_px`` lines; no cut runs through a handle."""
    n = cov.sum(axis).astype(float)
    m = len(n)
    if m <= 2 * min_px + 1:
        return -1, 0.0
    win = np.median(np.lib.stride_tricks.sliding_window_view(n, min_px), axis=1)  # win[i]: lines i .. i + min_px - 1
    idx = np.arange(min_px, m - min_px)
    jump = np.abs(win[idx + 1] - win[idx - min_px]) / cov.shape[axis]
    jump[blocked[idx]] = 0.0
    i = int(np.argmax(jump))
    if jump[i] <= 0.0:
        return -1, 0.0
    k = max(2, min_px // 2)
    lo, hi = max(int(idx[i]) - k, min_px), min(int(idx[i]) + k, m - min_px - 1)
    d = np.abs(np.diff(n))[lo:hi + 1]  # d[j - lo]: change between lines j and j + 1
    j = lo + int(np.argmax(d))
    cut = min(j + 1, m - min_px - 1) if n[j + 1] < n[j] else j  # the line dropped is on the emptier side
    if blocked[cut]:
        return -1, 0.0
    return cut, float(jump[i])


def _groove_cut(cov: np.ndarray, axis: int, min_px: int, q: CellConfig, blocked: np.ndarray,
                piece_sides: int) -> tuple[int, float]:
    """The middle of the widest band of lines across ``axis`` at most ``q.groove_px`` wide whose coverage is
    under ``q.groove_share`` of the cell's median line coverage, along the whole cell (in every piece
    ``piece_sides`` x ``min_px`` long), the ``min_px`` lines on each side covered at least half that level
    (median) and reaching it within ``groove_px`` / 2 lines of the band (steep walls), on a cell whose median
    line is covered ``groove_cover`` of its length (index in the cell, 1.0); else (-1, 0.0).

    Why: on a 1 cm TSDF mesh the 4 mm gap between two fronts is a groove 2-3 cm wide where the surface
    leaves the plane, unseen in the orthophoto too, so the seam shows no dark line to cut at, only a gap."""
    n = cov.sum(axis).astype(float)
    m, length = len(n), cov.shape[axis]
    if m <= 2 * min_px + 1 or not n.any():
        return -1, 0.0
    level = float(np.median(n[n > 0]))
    if level < q.groove_cover * length:
        return -1, 0.0  # a patchy plane: its holes line up by chance
    low = n < q.groove_share * level
    pieces = max(1, length // max(1, piece_sides * min_px))
    if pieces > 1:  # low in every piece where the lines beside it are covered
        for cp in np.array_split(cov, pieces, axis):
            npc = cp.sum(axis).astype(float)
            lev = float(np.median(npc[npc > 0])) if npc.any() else 0.0
            low &= npc < q.groove_share * max(lev, 1.0)
    lab, k = ndimage.label(low)
    wall = max(2, q.groove_px // 2)
    best, width = -1, 0
    for j in range(1, k + 1):
        idx = np.flatnonzero(lab == j)
        a, b = int(idx[0]), int(idx[-1])
        w = b - a + 1
        if w > q.groove_px or a - min_px < 0 or b + min_px >= m:
            continue
        if min(np.median(n[a - min_px:a]), np.median(n[b + 1:b + 1 + min_px])) < 0.5 * level:
            continue
        if min(n[a - wall:a].max(), n[b + 1:b + 1 + wall].max()) < 0.5 * level:
            continue  # a groove's walls are steep; an occluder's shadow or a hole's ragged edge slopes
        mid = (a + b) // 2
        if blocked[mid] or w <= width:
            continue
        best, width = mid, w
    return (best, 1.0) if best >= 0 else (-1, 0.0)


def _line_cut(ev: np.ndarray, cov: np.ndarray, axis: int, min_px: int, span: float, chunks: int,
              blocked: np.ndarray) -> tuple[int, float]:
    """Best split line on learned line evidence ``ev`` (index in the cell, share of the cell's covered
    length it covers), keeping ``min_px`` on each side and off ``blocked`` lines; lines covering less than
    ``span`` (or half of it in any of ``chunks`` pieces) score 0."""
    prof = _profile(ev, cov, axis)
    if len(prof) <= 2 * min_px:
        return -1, 0.0
    ok = (prof >= span) & (_profile(ev, cov, axis, chunks) >= 0.5 * span) & ~blocked
    inner = np.where(ok, prof, 0.0)[min_px:len(prof) - min_px]
    i = _plateau_middle(inner)
    return i + min_px, float(inner[i])


def _plateau_middle(v: np.ndarray) -> int:
    """Index of the middle of the run of equal values around ``v``'s first maximum: a line drawn a few px
    wide (learned segments widened by ``lines.tol``) is cut at its centre, not its edge."""
    i = int(np.argmax(v))
    j = i
    while j + 1 < len(v) and v[j + 1] == v[i]:
        j += 1
    return (i + j) // 2


def pane_boxes(panes: np.ndarray, margin_px: int, core: float = 0.5) -> list[tuple[int, int, int, int]]:
    """Boxes (c0, r0, c1, r1) of the glass panes in mask ``panes``, grown by ``margin_px``: each pane's
    columns holding at least ``core`` of its fullest column's pixels, and its rows likewise.

    Why: a pane lies inside one door. Painted with its frame's colour it still differs from the frame a
    little (shading, the frame's inner edge), and the splitter cut glass doors along a pane's edge or
    across it at a shelf seen through the glass (glass tuning: a cupboard's three glass doors cut at their
    panes' edges, a wall cabinet's glass door halved across its pane). The core, not the bounding box: a
    pane that leaked through a speck of the frame into the gap beside it barred the seam there."""
    if not panes.any():
        return []
    n, lab, stats, _ = cv2.connectedComponentsWithStats(panes.astype(np.uint8), connectivity=CONNECTIVITY)
    h, w = panes.shape
    out = []
    for k in range(1, n):
        x, y, bw, bh = (int(v) for v in stats[k, :4])
        me = lab[y:y + bh, x:x + bw] == k
        cols, rows = me.sum(0), me.sum(1)
        cs, rs = np.flatnonzero(cols >= core * cols.max()), np.flatnonzero(rows >= core * rows.max())
        out.append((max(0, x + int(cs[0]) - margin_px), max(0, y + int(rs[0]) - margin_px),
                    min(w, x + int(cs[-1]) + 1 + margin_px), min(h, y + int(rs[-1]) + 1 + margin_px)))
    return out


def _pane_blocks(c: Cell, panes: Sequence[tuple[int, int, int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Columns and rows of cell ``c`` (local indices) that a cut may not take: those of every pane box
    overlapping the cell, where a cut would run through the pane or along its edge."""
    pc = np.zeros(c.c1 - c.c0, bool)
    pr = np.zeros(c.r1 - c.r0, bool)
    for b0, a0, b1, a1 in panes:
        if b0 < c.c1 and b1 > c.c0 and a0 < c.r1 and a1 > c.r0:
            pc[max(b0, c.c0) - c.c0:min(b1, c.c1) - c.c0] = True
            pr[max(a0, c.r0) - c.r0:min(a1, c.r1) - c.r0] = True
    return pc, pr


def _split(c: Cell, vert: np.ndarray, horiz: np.ndarray, cov: np.ndarray, p: SeamConfig, q: CellConfig, min_px: int,
           depth: int, bc: np.ndarray, br: np.ndarray, handles: list[Handle], g: tuple[np.ndarray, np.ndarray],
           col: tuple[np.ndarray, np.ndarray], learned: LearnedLines | None = None, strip_px: int = 0, pull_px: int = 0,
           panes: Sequence[tuple[int, int, int, int]] = ()) -> list[Cell]:
    """Recursive guillotine split at the strongest straight seam (``_dip_cut``), else at a line that
    ``learned`` line segments support, else at the most prominent seam by valley counts.
    Inside a cell holding handles, a horizontal cut must leave a handle on both sides (glossy fronts
    reflect horizontal table and shelf edges at a constant height; a drawer above a door carries its own
    handle) — unless the side without one is a strip at most ``strip_px`` tall along the cell's top or
    bottom edge (``cells.edge_strip``): a plinth or a worktop's edge, cut off and dropped; or the cut is a
    straight dark seam (a dip, not a valley count: a bar's own rim makes those) within ``pull_px`` of a
    horizontal bar's top edge (``cells.edge_pull``): the seam an edge pull hangs from, whose front's
    neighbour above shows no handle when its own pull lies on the outline. No cut runs through or along a
    glass pane of ``panes`` (grid boxes c0, r0, c1, r1, grown by their margin; ``pane_boxes``)."""
    if depth >= q.max_split_depth:
        return [c]
    sl = (slice(c.r0, c.r1), slice(c.c0, c.c1))
    pc, pr = _pane_blocks(c, panes)
    bcl, brl = bc[c.c0:c.c1] | pc, br[c.r0:c.r1] | pr
    if q.outline_step > 0:  # an L-shaped outline splits at its corner before any seam is sought
        ov, sv = _outline_cut(cov[sl], 0, min_px, bcl)
        oh, sh = _outline_cut(cov[sl], 1, min_px, brl)
        if max(sv, sh) >= q.outline_step:  # columns first: a run splits into units, a unit into fronts
            if sv >= q.outline_step:
                a = Cell(c.c0, c.r0, c.c0 + ov, c.r1, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts)
                b = Cell(c.c0 + ov + 1, c.r0, c.c1, c.r1, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts)
            else:
                a = Cell(c.c0, c.r0, c.c1, c.r0 + oh, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts)
                b = Cell(c.c0, c.r0 + oh + 1, c.c1, c.r1, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts)
            return (_split(a, vert, horiz, cov, p, q, min_px, depth + 1, bc, br, handles, g, col, learned, strip_px, pull_px, panes)
                    + _split(b, vert, horiz, cov, p, q, min_px, depth + 1, bc, br, handles, g, col, learned, strip_px, pull_px, panes))
    cv_, sc_v = _dip_cut(g[0][sl], cov[sl], 0, min_px, p, bcl)   # profile over columns
    ch_, sc_h = _dip_cut(g[1][sl], cov[sl], 1, min_px, p, brl)   # profile over rows
    if p.ridges and not any(c.c0 <= h.center[0] < c.c1 and c.r0 <= h.center[1] < c.r1 for h in handles):
        # a handle-less cell: a straight row brighter than both sides along the whole cell is a seam too
        # (the top edge of the drawer below, lit from above; a vertical gap catches no such light)
        rh_, rs_h = _dip_cut(-g[1][sl], cov[sl], 1, min_px, p, brl)
        if rs_h > sc_h:
            ch_, sc_h = rh_, rs_h
    sc_v = sc_v if sc_v >= p.dip_z else 0.0
    sc_h = sc_h if sc_h >= p.dip_z else 0.0
    dip_v, dip_h = sc_v > 0.0, sc_h > 0.0
    if p.step_over_dip or not (dip_v or dip_h):
        # a colour step along the whole cell (a front of another colour than its surround or its
        # neighbour); with ``step_over_dip`` it wins where it is stronger than the best dark line (a
        # shaker door's frame casts a straight dark line a few cm inside its own edge)
        sv_, st_v = _dip_cut(col[0][sl], cov[sl], 0, min_px, p, bcl, _step_scores)
        sh_, st_h = _dip_cut(col[1][sl], cov[sl], 1, min_px, p, brl, _step_scores)
        st_v = st_v if st_v >= p.step_z else 0.0
        st_h = st_h if st_h >= p.step_z else 0.0
        if st_v > sc_v:
            cv_, sc_v, dip_v = sv_, st_v, False
        if st_h > sc_h:
            ch_, sc_h, dip_h = sh_, st_h, False
    straight = int(dip_v if sc_v >= sc_h else dip_h) if max(sc_v, sc_h) > 0.0 else 0
    if max(sc_v, sc_h) == 0.0 and q.groove_share > 0:
        # a groove: a narrow band the scan's surface leaves along the whole cell (a TSDF seam)
        cv_, sc_v = _groove_cut(cov[sl], 0, min_px, q, bcl, p.piece_sides)
        ch_, sc_h = _groove_cut(cov[sl], 1, min_px, q, brl, p.piece_sides)
        straight = int(max(sc_v, sc_h) > 0.0)
    if max(sc_v, sc_h) == 0.0 and learned is not None:
        # a straight line that the learned segments of several views agree on (a seam in a glossy or
        # evenly lit front shows no dark line)
        cv_, sc_v = _line_cut(learned.vert[sl], cov[sl], 0, min_px, learned.span, p.span_chunks,
                              learned.blocked_c[c.c0:c.c1] | pc)
        ch_, sc_h = _line_cut(learned.horiz[sl], cov[sl], 1, min_px, learned.span, p.span_chunks,
                              learned.blocked_r[c.r0:c.r1] | pr)
        straight = int(max(sc_v, sc_h) > 0.0)
    if max(sc_v, sc_h) == 0.0:
        cv_, sc_v = _best_cut(vert[sl], cov[sl], 0, min_px, p, bcl)
        ch_, sc_h = _best_cut(horiz[sl], cov[sl], 1, min_px, p, brl)
        sc_v = sc_v if sc_v >= p.prominence else 0.0
        sc_h = sc_h if sc_h >= p.prominence_h else 0.0
    mine = [h for h in handles if c.c0 <= h.center[0] < c.c1 and c.r0 <= h.center[1] < c.r1]
    if sc_h and mine and not (q.knobs_any_side and all(h.knob for h in mine)):
        cut = c.r0 + ch_
        above, below = any(h.center[1] < cut for h in mine), any(h.center[1] > cut for h in mine)
        if not (above and below) and not (dip_h and sc_h >= sc_v and _hangs_from(mine, cut, pull_px)):
            if sc_h >= sc_v and _edge_strip(c, cut, above, strip_px, mine):
                # the strip is no front: the cell goes on without it, its sides as they were
                rest = (Cell(c.c0, c.r0, c.c1, cut, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts) if above
                        else Cell(c.c0, cut + 1, c.c1, c.r1, cut_sides=c.cut_sides, seam_cuts=c.seam_cuts))
                return _split(rest, vert, horiz, cov, p, q, min_px, depth + 1, bc, br, mine, g, col, learned, strip_px, pull_px, panes)
            sc_h = 0.0
    if max(sc_v, sc_h) == 0.0:
        return [c]
    n, k = c.cut_sides + 1, c.seam_cuts + straight
    if sc_v >= sc_h:
        a = Cell(c.c0, c.r0, c.c0 + cv_, c.r1, cut_sides=n, seam_cuts=k)
        b = Cell(c.c0 + cv_ + 1, c.r0, c.c1, c.r1, cut_sides=n, seam_cuts=k)
    else:
        a = Cell(c.c0, c.r0, c.c1, c.r0 + ch_, cut_sides=n, seam_cuts=k)
        b = Cell(c.c0, c.r0 + ch_ + 1, c.c1, c.r1, cut_sides=n, seam_cuts=k)
        if not q.strip_seams and strip_px > 0:
            # a cut that takes a strip off the cell's top or bottom edge (a skirting board, a plinth, a
            # cornice) is no seam of the larger side: a plain wall cut so is not cut out by seams
            if a.r1 - a.r0 <= strip_px < b.r1 - b.r0:
                b.seam_cuts = c.seam_cuts
            elif b.r1 - b.r0 <= strip_px < a.r1 - a.r0:
                a.seam_cuts = c.seam_cuts
    return (_split(a, vert, horiz, cov, p, q, min_px, depth + 1, bc, br, mine, g, col, learned, strip_px, pull_px, panes)
            + _split(b, vert, horiz, cov, p, q, min_px, depth + 1, bc, br, mine, g, col, learned, strip_px, pull_px, panes))


def _split_at_pulls(c: Cell, g: np.ndarray, cov: np.ndarray, min_px: int, pull_px: int, p: SeamConfig,
                    panes: Sequence[tuple[int, int, int, int]] = ()) -> list[Cell]:
    """Cut a cell along the seam an edge pull hangs from: for its horizontal bar lowest down first, the row
    within ``pull_px`` above the bar's top edge where the brightness (``g``, handles filled in along rows)
    dips most, when that dip scores at least ``seams.between_z`` noise units (the bar vouches for the seam
    as a second handle does in ``_between``) and leaves ``min_px`` rows above. Why: a chest's lips sit on
    the seams above them; with the top drawer's lip on the outline, each seam had a handle below and none
    above, and a white-on-white TSDF seam is too faint for a straight cut by itself (``seams.dip_z``).
    No cut runs through a glass pane of ``panes``: a bar on a glass door's bottom rail hangs from no seam."""
    if pull_px <= 0:
        return [c]
    pr = _pane_blocks(c, panes)[1]
    bars = sorted((h for h in c.handles if h.horizontal and not h.knob), key=lambda h: -h.box[1])
    for h in bars:
        lo, hi = h.box[1] - pull_px, h.box[1] + 1
        if lo - c.r0 < min_px:
            continue
        sl = (slice(c.r0, c.r1), slice(c.c0, c.c1))
        z = _dip_scores(g[sl], cov[sl], 1, min_px, p)[lo - c.r0:hi - c.r0]
        if not len(z) or z.max() < p.between_z:
            continue
        cut = lo + int(np.argmax(z))
        if pr[cut - c.r0]:
            continue
        a = Cell(c.c0, c.r0, c.c1, cut, [k for k in c.handles if k.center[1] < cut], c.cut_sides + 1, c.seam_cuts)
        b = Cell(c.c0, cut + 1, c.c1, c.r1, [k for k in c.handles if k.center[1] >= cut], c.cut_sides + 1, c.seam_cuts)
        return _split_at_pulls(a, g, cov, min_px, pull_px, p, panes) + [b]
    return [c]


def _hangs_from(handles: list[Handle], cut: int, pull_px: int) -> bool:
    """Whether a horizontal bar among ``handles`` has its top edge within ``pull_px`` rows of the horizontal
    cut at row ``cut``: an edge pull hanging from the seam above it, a lip along a drawer's top edge (a bar
    mounted on a front stands clear of its edges; a reflected shelf edge lines up with no handle's edge).
    Only the top edge: under a bar lie its own shadow and, on an oven's drop door, the window's top rail."""
    return pull_px > 0 and any(h.horizontal and not h.knob and abs(h.box[1] - cut) <= pull_px for h in handles)


def _edge_strip(c: Cell, cut: int, above: bool, strip_px: int, handles: list[Handle]) -> bool:
    """Whether a horizontal cut at row ``cut`` leaves, on the side without handles, a strip along the cell's
    top or bottom edge at most ``strip_px`` tall (the handles lie ``above`` the cut or below it), no handle's
    box reaching into it."""
    if strip_px <= 0:
        return False
    if above:  # the strip is below the cut, down to the cell's bottom edge
        return c.r1 - cut <= strip_px and all(h.box[3] <= cut for h in handles)
    return cut - c.r0 <= strip_px and all(h.box[1] > cut for h in handles)


def _between(g: np.ndarray, ev: np.ndarray, cov: np.ndarray, axis: int, lo: int, hi: int, min_px: int, p: SeamConfig,
             learned: np.ndarray | None = None, span: float = 1.0, centres: tuple[int, int] | None = None,
             seam_only: bool = False) -> int | None:
    """The line in [lo, hi) of a cell's pixels where two handled fronts meet: the line ``learned`` line
    evidence covers most, when it covers at least ``span`` of the cell; else the strongest straight seam
    (``_dip_scores`` >= ``between_z`` noise units), sought between the handles' ``centres`` when given
    (a handle's box, grown by the bar closing and blurred by misregistration, reaches a few px over the
    seam beside it: a drawer's seam just above the handle of the door below was outside [lo, hi) and the
    cut fell halfway up the drawer); else the most seam-like line by valley counts (covering more than
    ``between_span``), else the middle (``seam_only``: None, no line)."""
    if hi - lo < 1:
        return None if seam_only else (lo + hi) // 2
    if learned is not None:
        prof = _profile(learned, cov, axis)[lo:hi]
        if prof.max() >= span:
            return lo + _plateau_middle(prof)
    a, b = (lo, hi) if centres is None else (min(lo, centres[0] + 1), max(hi, centres[1]))
    z = _dip_scores(g, cov, axis, min_px, p)[a:b]
    if len(z) and z.max() >= p.between_z:
        return a + int(np.argmax(z))
    sl = (slice(None), slice(lo, hi)) if axis == 0 else (slice(lo, hi), slice(None))
    prof = _profile(ev[sl], cov[sl], axis)
    if prof.max() > p.between_span:
        return lo + int(np.argmax(prof))
    return None if seam_only else (lo + hi) // 2


def _bar_seen_twice(a: Handle, b: Handle) -> bool:
    """Whether two horizontal bars share more than ``_TWICE_PX`` columns: no vertical seam runs between
    them, so they are one bar painted at two heights (views looking down at different angles paint a proud
    bar lower on the front the steeper they look; RedKitchen's corner door got two such pieces, 2.4 cm
    apart, and was cut in two between them). Two doors' bars side by side leave a gap: bars nearer than
    ``handles.join_gap`` along a row are joined into one blob before this."""
    if not (a.horizontal and b.horizontal) or a.knob or b.knob:
        return False
    return min(a.box[2], b.box[2]) - max(a.box[0], b.box[0]) > _TWICE_PX


def _nested(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    """Whether the columns of one pixel box lie within those of the other."""
    return (a[0] <= b[0] and b[2] <= a[2]) or (b[0] <= a[0] and a[2] <= b[2])


def _pitch_split(c: Cell, g: np.ndarray, cov: np.ndarray, min_px: int, p: SeamConfig, tol: float) -> list[Cell] | None:
    """A cell holding a column of two or more horizontal bars at one pitch P (each step within ``tol`` x P of
    their median), and k = n or n + 1 pitches tall (within ``tol`` x P), with no straight seam
    (``seams.between_z``) anywhere between two of them: cut into k drawers of equal height, each bar in
    its own (None where the cell is not such a stack).

    Why: between two bars and no seam, the cut fell halfway, right for centred handles but half a drawer off
    for edge pulls along the drawers' top edges (a white TSDF chest shows no seam; its top drawer's pull lies
    on the outline and is not found, hence n + 1). A stack of equal drawers puts its seams on the pitch
    grid anchored at the cell's edges whichever way its handles sit."""
    hs = sorted(c.handles, key=lambda h: h.center[1])
    n = len(hs)
    if n < 2 or not all(h.horizontal and not h.knob for h in hs):
        return None
    ys = np.array([h.center[1] for h in hs])
    steps = np.diff(ys)
    pitch = float(np.median(steps))
    if pitch < min_px or np.abs(steps - pitch).max() > tol * pitch:
        return None
    if min(h.box[2] for h in hs) <= max(h.box[0] for h in hs):
        return None  # not one column: some bars share no columns
    height = c.r1 - c.r0
    k = int(round(height / pitch))
    if k not in (n, n + 1) or abs(height - k * pitch) > tol * pitch:
        return None
    sl = (slice(c.r0, c.r1), slice(c.c0, c.c1))
    z = _dip_scores(g[sl], cov[sl], 1, min_px, p)
    if len(z) and z[int(ys[0]) - c.r0:int(ys[-1]) - c.r0 + 1].max(initial=0.0) >= p.between_z:
        return None  # a seam shows: the usual cuts find it
    cuts = [c.r0 + int(round(j * height / k)) for j in range(1, k)]
    edges = [c.r0] + cuts + [c.r1]
    out = [Cell(c.c0, a if j == 0 else a + 1, c.c1, b, [h for h in hs if a <= h.center[1] < b],
                c.cut_sides + (j > 0) + (j < k - 1), c.seam_cuts) for j, (a, b) in enumerate(zip(edges[:-1], edges[1:]))]
    if any(len(x.handles) > 1 for x in out) or sum(len(x.handles) for x in out) != n:
        return None
    return out


def _door_pair_knobs(a: tuple[int, int, int, int], b: tuple[int, int, int, int], c0: int, c1: int,
                     p: SeamConfig) -> bool:
    """Whether knob boxes ``a`` (left) and ``b`` in a cell spanning columns [c0, c1) are a door pair's
    (``seams.knob_pair_gap``): at one height, apart by at least a knob's width and at most that share of
    the cell, their midpoint by the cell's middle. Why: a pair of doors has its knobs by the stiles where
    the doors meet; a wide drawer's two knobs sit at its quarters, half its width apart."""
    if p.knob_pair_gap <= 0 or a[1] >= b[3] or b[1] >= a[3]:
        return False
    w, gap = c1 - c0, b[0] - a[2]
    mid = (a[2] + b[0]) / 2
    return (max(a[2] - a[0], b[2] - b[0]) <= gap <= p.knob_pair_gap * w
            and abs(mid - (c0 + c1) / 2) <= p.knob_pair_centre * w)


def _split_handles(c: Cell, vert: np.ndarray, horiz: np.ndarray, cov: np.ndarray, min_px: int, g: tuple[np.ndarray, np.ndarray],
                   p: SeamConfig, learned: LearnedLines | None = None,
                   panes: Sequence[tuple[int, int, int, int]] = ()) -> list[Cell]:
    """Split a cell between consecutive handles (side by side: at the best column between them;
    stacked: at the best row), recursively, so every cell ends with at most one handle per row/column;
    never through or along a glass pane of ``panes`` (one door: its second "handle" is the frame's shading
    or a shelf's lip behind the glass)."""
    if len(c.handles) < 2:
        return [c]
    pc, pr = _pane_blocks(c, panes)
    hs = sorted(c.handles, key=lambda h: h.center[0])
    xs = [h.center[0] for h in hs]
    ys = sorted(h.center[1] for h in hs)
    span_x, span_y = xs[-1] - xs[0], ys[-1] - ys[0]
    pair = (len(hs) == 2 and hs[0].knob and hs[1].knob and c.c1 - c.c0 >= 2 * min_px
            and _door_pair_knobs(hs[0].box, hs[1].box, c.c0, c.c1, p))
    if max(span_x, span_y) < min_px and not pair:  # a door pair's knobs may sit closer than a front is wide
        return [c]
    args = (vert, horiz, cov, min_px, g, p, learned, pc, pr, pair)
    first, second = (_cut_side_by_side, _cut_stacked) if span_x >= span_y else (_cut_stacked, _cut_side_by_side)
    halves = first(c, *args)
    if halves is not None and p.clear_of_handles and _through_handle(c, halves):
        other = second(c, *args)
        if other is not None and not _through_handle(c, other):
            halves = other
    if halves is None:
        return [c]
    a, b = halves
    return (_split_handles(a, vert, horiz, cov, min_px, g, p, learned, panes)
            + _split_handles(b, vert, horiz, cov, min_px, g, p, learned, panes))


def _through_handle(c: Cell, halves: tuple[Cell, Cell]) -> bool:
    """Whether the cut between ``halves`` runs through one of ``c``'s handles, leaving at least
    ``_THROUGH_SHARE`` of it on each side (a bar is one front's: a cut across it is no seam; a handle's box,
    grown by the bar closing and blurred by misregistration, reaches a few px over the seam beside it)."""
    a, b = halves
    side = a.c1 < b.c0  # side by side: the cut is the column between them
    lo, hi = (a.c1, b.c0) if side else (a.r1, b.r0)
    for h in c.handles:
        h0, h1 = (h.box[0], h.box[2]) if side else (h.box[1], h.box[3])
        if min(lo - h0, h1 - hi) >= _THROUGH_SHARE * (h1 - h0):
            return True
    return False


def _cut_side_by_side(c: Cell, vert: np.ndarray, horiz: np.ndarray, cov: np.ndarray, min_px: int,
                      g: tuple[np.ndarray, np.ndarray], p: SeamConfig, learned: LearnedLines | None,
                      pc: np.ndarray, pr: np.ndarray, pair: bool) -> tuple[Cell, Cell] | None:
    """``c`` cut at the best column in the widest gap between its handles' centres (None: no such cut)."""
    hs = sorted(c.handles, key=lambda h: h.center[0])
    xs = [h.center[0] for h in hs]
    k = int(np.argmax(np.diff(xs)))
    if _nested(hs[k].box, hs[k + 1].box):
        return None  # one lies across the other's columns (a bar over a frame rail): not side by side
    if _bar_seen_twice(hs[k], hs[k + 1]):
        return None
    lo, hi = int(hs[k].box[2]), int(hs[k + 1].box[0])
    if hi - lo < 2:
        lo, hi = int(xs[k]), int(xs[k + 1])
    rs, cs = slice(c.r0, c.r1), slice(c.c0, c.c1)
    knobs = p.knob_seam and hs[k].knob and hs[k + 1].knob
    at = _between(g[0][rs, cs], vert[rs, cs], cov[rs, cs], 0, lo - c.c0, hi - c.c0, min_px, p,
                  None if learned is None else learned.vert[rs, cs], 1.0 if learned is None else learned.span,
                  (int(xs[k]) - c.c0, int(xs[k + 1]) - c.c0), seam_only=knobs)
    if at is None and pair:
        at = (hs[0].box[2] + hs[1].box[0]) // 2 - c.c0
    if at is None:
        return None  # two knobs side by side with no seam between them: one wide drawer's or a panel's
    cut = c.c0 + at
    a = Cell(c.c0, c.r0, cut, c.r1, [h for h in c.handles if h.center[0] < cut], c.cut_sides + 1, c.seam_cuts)
    b = Cell(cut + 1, c.r0, c.c1, c.r1, [h for h in c.handles if h.center[0] >= cut], c.cut_sides + 1, c.seam_cuts)
    if not a.handles or not b.handles or not (c.c0 < cut < c.c1 - 1) or pc[cut - c.c0]:
        return None  # handles overlapping across the cut (a bar seen twice): nothing to separate
    return a, b


def _cut_stacked(c: Cell, vert: np.ndarray, horiz: np.ndarray, cov: np.ndarray, min_px: int,
                 g: tuple[np.ndarray, np.ndarray], p: SeamConfig, learned: LearnedLines | None,
                 pc: np.ndarray, pr: np.ndarray, pair: bool) -> tuple[Cell, Cell] | None:
    """``c`` cut at the best row in the widest gap between its handles' centres (None: no such cut)."""
    hs = sorted(c.handles, key=lambda h: h.center[1])
    ys = [h.center[1] for h in hs]
    k = int(np.argmax(np.diff(ys)))
    lo, hi = int(hs[k].box[3]), int(hs[k + 1].box[1])
    if hi - lo < 2:
        lo, hi = int(ys[k]), int(ys[k + 1])
    rs, cs = slice(c.r0, c.r1), slice(c.c0, c.c1)
    cut = c.r0 + _between(g[1][rs, cs], horiz[rs, cs], cov[rs, cs], 1, lo - c.r0, hi - c.r0, min_px, p,
                          None if learned is None else learned.horiz[rs, cs], 1.0 if learned is None else learned.span,
                          (int(ys[k]) - c.r0, int(ys[k + 1]) - c.r0))
    a = Cell(c.c0, c.r0, c.c1, cut, [h for h in c.handles if h.center[1] < cut], c.cut_sides + 1, c.seam_cuts)
    b = Cell(c.c0, cut + 1, c.c1, c.r1, [h for h in c.handles if h.center[1] >= cut], c.cut_sides + 1, c.seam_cuts)
    if not a.handles or not b.handles or not (c.r0 < cut < c.r1 - 1) or pr[cut - c.r0]:
        return None
    return a, b
