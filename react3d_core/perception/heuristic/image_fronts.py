"""Openable fronts found in the colour frames: planes → fused orthophotos → seam/handle cells → fronts.

The mesh-only rules (fronts.py) need seams in the mesh; real scans have none. Here each large
vertical plane of the mesh is photographed from all the views that see it (orthophoto.py), split at
the seams and between the handles the photos show (front_cells.py), and every door/drawer-sized cell
with a handle — or cut out by seams on at least two sides and not tile-sized, or on one side where the
plane's outline closes it (``plain_fronts_kept``) — becomes a front whose faces are the plane's faces
inside the cell. Joint type and hinge side come from the same rules as
mesh fronts (handle position and shape, neighbours).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import cv2
import networkx as nx
import numpy as np

from ...config.heuristic import CellConfig, FloorConfig, FrontRulesConfig, HandleConfig, HeuristicConfig, ImageConfig, RoomWallConfig
from ...data.frames import Frame
from ...data.mesh import TriMesh
from ...geometry import weighted_median
from ...raster import Rasterizer
from .behind_glass import PaneRegion
from .front_cells import Cell, Handle, find_handles, off_background, off_local, off_threshold, split_cells, stand_out
from .fronts import Front, _joint, _neighbours, doors_in_rows, u_overlap
from .line_evidence import LineSupport, line_support
from .orthophoto import ColourCalibration, Orthophoto, build_orthophotos
from .constants import CONNECTIVITY, MIN_KERNEL, NEIGHBOURS, XYZ
from .plane_surface import PlaneSurface, cast_surface, flat_surface
from .planes import Plane, share_behind, vertical_planes
from .portholes import find_portholes, porthole_core

_MIN_CUT_SIDES = 2  # a handle-less cell cut out on this many sides is cut out by the plane's seams
_MIN_SURFACE_DIV = 3  # the surface around a mesh handle: faces in at least a third of the window's blocks
_EDGE_NEAR = 0.01  # m: a cell this close to the coverage's top or bottom row runs along its edge
_PORTHOLE_COVERED = 0.5  # a cell's front covering this share of a porthole door is the plate around it
_PORTHOLE_SPAN = 0.9  # a strip spanning this share of a porthole door's width is the plate
_ANY_OUTWARD_DEG = 90.0  # deg: a face tilted up to this from a plane's normal still faces out of it


@dataclass
class ImageFronts:
    """Fronts found in the images, the planes they came from, their orthophotos and the colour
    calibration (kept for reports and debugging)."""

    fronts: list[Front]
    vetoed: list[int]  # indices of mesh fronts the photos show to be clutter (tiles, posters)
    planes: list[Plane]
    orthophotos: list[Orthophoto]
    calibration: ColourCalibration
    registration: dict[int, ColourCalibration] = field(default_factory=dict)  # per-view correction by frame index
    lines: list[LineSupport] = field(default_factory=list)  # learned line support per plane (empty: not used)
    panes: list[PaneRegion] = field(default_factory=list)  # planes' glass panes, grown by their frames


def floor_height(mesh: TriMesh, cfg: FloorConfig) -> float | None:
    """Height of the floor: the area-weighted median height of the lowest ``band``-high slice of
    faces facing up (normal z above ``min_up``) holding ``min_area`` m²; None when no slice does (a
    scan without its floor)."""
    up = mesh.face_normals[:, 2] > cfg.min_up
    if not up.any() or cfg.min_area <= 0:
        return None
    z, a = mesh.face_centroids[up, 2], mesh.face_areas[up]
    bins = np.floor((z - z.min()) / cfg.band).astype(int)
    full = np.flatnonzero(np.bincount(bins, weights=a) >= cfg.min_area)
    if not len(full):
        return None
    zb, ab = z[bins == full[0]], a[bins == full[0]]
    order = np.argsort(zb)
    cum = np.cumsum(ab[order])
    return float(zb[order][np.searchsorted(cum, 0.5 * cum[-1])])  # area-weighted median of the band


def floor_level(mesh: TriMesh, cfg: FloorConfig) -> float:
    """:func:`floor_height`, else the mesh's lowest point (rules that need a floor always get one)."""
    floor = floor_height(mesh, cfg)
    return float(mesh.vertices[:, 2].min()) if floor is None else floor


def off_the_floor(fronts: list[Front], floor: float | None, gap: float, stacked: set[int] | None = None) -> list[Front]:
    """Fronts without a handle whose bottom edge is within ``gap`` of ``floor`` dropped (None: all kept),
    except those whose ids are in ``stacked``: the bottom drawer of a pedestal on a recessed plinth reaches
    the floor in the scan, and a wall is not cut into a column of drawer-sized cells (``stacks``)."""
    if floor is None:
        return list(fronts)
    keep = stacked or set()
    return [f for f in fronts if f.handle_points is not None or f.extent_v[0] > floor + gap or id(f) in keep]


EXACT_NORMAL = 3e-4
"""Normals equal to this (about 0.02 degrees) are one modelled surface's: a scan's faces, fused from noisy
depth and decimated or not, never share a normal to this precision over a plane."""


MODELLED_GROUP = 0.01
"""A group of faces with one exact normal counts towards a modelled plane from this share of its area."""


def modelled_surface(mesh: TriMesh, faces: np.ndarray, share: float) -> bool:
    """Whether at least ``share`` of the faces' area lies in groups of two or more faces with one exact
    normal (``EXACT_NORMAL``), each group holding 1 % of the area or more: a modelled scene's plane (CAD, a
    synthetic generator's clean mesh: flat fields, frames and panels each one normal), not a scan's, whose
    faces almost never share a normal to that precision (0: never)."""
    if share <= 0 or not len(faces):
        return False
    a = mesh.face_areas[faces]
    key = np.round(mesh.face_normals[faces] / EXACT_NORMAL).astype(np.int64)
    _, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    counts, areas = np.bincount(inv), np.bincount(inv, a)
    shared = (counts >= 2) & (areas >= MODELLED_GROUP * a.sum())
    return bool(areas[shared].sum() >= share * a.sum())


def coarse_faces(mesh: TriMesh, faces: np.ndarray, edge: float) -> bool:
    """Whether a plane's faces are too coarse for their centroids to paint it: the area-weighted median of
    their size (sqrt(2 * area), a right triangle's leg) exceeds ``edge`` m (0: never). A fused scan's 1 cm
    faces are painted by centroids closed over ``image.coverage_close``; a decimated scan's 2-5 cm faces
    leave most of a plane unpainted, so its coverage and handles are read from rays instead."""
    if edge <= 0 or not len(faces):
        return False
    a = mesh.face_areas[faces]
    return weighted_median(np.sqrt(2.0 * a), a) > edge


def coverage_from_faces(o: Orthophoto, mesh: TriMesh, min_area: float, close: float, slab: float = 0.0,
                        tilt_deg: float = 0.0) -> np.ndarray:
    """Grid pixels covered by the plane's own faces (centroids splatted, holes up to ``close`` m closed,
    fragments under ``min_area`` m² dropped): ``image.surface_rays`` off. Decimated scans' faces lie
    farther apart than ``close``, so their planes come out mostly uncovered. With ``tilt_deg`` > 0 the
    faces within ``slab`` m of the plane whose normals are tilted from its own by at most ``tilt_deg``
    paint it too (``slab_faces``)."""
    faces = o.plane.faces
    if tilt_deg > 0:
        faces = np.union1d(faces, slab_faces(mesh, o.plane, slab, tilt_deg))
    r, c, ok = o.pixels_of(mesh.face_centroids[faces])
    cov = np.zeros(o.n_views.shape, np.uint8)
    cov[r[ok], c[ok]] = 1
    k = max(MIN_KERNEL, int(round(close / o.res)) | 1)
    cov = cv2.morphologyEx(cov, cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
    cov = cov.astype(np.uint8)
    # stray fragments (bits of floor or wall that happen to lie in the plane) are not part of it
    n, lab, stats, _ = cv2.connectedComponentsWithStats(cov, connectivity=CONNECTIVITY)
    keep = np.zeros(n, bool)
    keep[1:] = stats[1:, cv2.CC_STAT_AREA] * o.res ** 2 >= min_area
    return keep[lab]


def slab_faces(mesh: TriMesh, plane: Plane, slab: float, tilt_deg: float) -> np.ndarray:
    """Faces whose centroids lie within ``slab`` m of ``plane`` and inside its extent, facing its way with
    normals tilted from its normal by at most ``tilt_deg``.

    Why: a plane holds the faces whose normals lie within ``planes.angle_tol_deg`` of its own. A fused
    scan of a raised-panel or shaker front rounds its bevels and frame into a surface whose faces tilt
    by 15-40 degrees, all within a centimetre or two of the front's plane, so only 25-40 % of such a
    front was its plane's and its cell fell under ``cells.min_seen``. The worktop's top and the floor
    face up, not out, so they stay out."""
    cen, nrm = mesh.face_centroids, mesh.face_normals
    p = plane
    near = np.flatnonzero((np.abs(cen @ p.n - p.d) <= slab) & (nrm @ p.n >= np.cos(np.radians(tilt_deg))))
    uu, vv = cen[near] @ p.u, cen[near, 2]
    inside = ((uu >= p.extent_u[0]) & (uu <= p.extent_u[1]) & (vv >= p.extent_v[0]) & (vv <= p.extent_v[1]))
    return near[inside]


def seen_near(seen: np.ndarray, res: float, reach: float) -> np.ndarray:
    """Pixels within ``reach`` m of one that ``seen`` marks: what the views show of a plane, with its
    holes (handle shadows) and the outlines the depth-edge erosion took off every view, but not the
    plane's stretches that no view sees (a wall behind cabinets: the scan may hold it, no camera did)."""
    r = int(round(reach / res))
    if r <= 0:
        return seen.copy()
    return cv2.dilate(seen.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))).astype(bool)


def coverage_map(o: Orthophoto, flat: np.ndarray, min_area: float, close: float) -> np.ndarray:
    """Grid pixels where the plane is: the scan surface lying flat in its slab (``flat``, from
    ``plane_surface.flat_surface``), holes up to ``close`` m closed, fragments under ``min_area`` m² dropped."""
    k = max(MIN_KERNEL, int(round(close / o.res)) | 1)
    cov = cv2.morphologyEx(flat.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
    # stray fragments (bits of floor or wall that happen to lie in the plane) are not part of it
    n, lab, stats, _ = cv2.connectedComponentsWithStats(cov, connectivity=CONNECTIVITY)
    keep = np.zeros(n, bool)
    keep[1:] = stats[1:, cv2.CC_STAT_AREA] * o.res ** 2 >= min_area
    return keep[lab]


def enclosed_holes(seen: np.ndarray, outline: np.ndarray, res: float, min_thick: float,
                   row_limit: int | None = None) -> np.ndarray:
    """Horizontal unseen holes inside the outline, at least ``min_thick`` tall, that do not reach the
    outline's border (and, with ``row_limit``, lie wholly above that orthophoto row).

    A bar handle hides the front just behind and above it from every view that looks up at it (wall
    cabinets), so on a scan its footprint is a handle-shaped hole with the handle's colour nowhere in
    the orthophoto; find_handles judges the holes' size and shape like colour blobs. Vertical and thin
    holes are left out: those are the unseen gaps between fronts. Below eye level the views look down
    on a bar and see its colour; holes there are left to the colour test."""
    hole = (outline & ~seen).astype(np.uint8)
    n, lab, stats, _ = cv2.connectedComponentsWithStats(hole, connectivity=CONNECTIVITY)
    if n <= 1:
        return np.zeros(seen.shape, bool)
    border = cv2.dilate((~outline).astype(np.uint8), NEIGHBOURS).astype(bool)
    border[[0, -1], :] = True
    border[:, [0, -1]] = True
    w, h = stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]
    keep = (w >= h) & (h * res >= min_thick)
    if row_limit is not None:
        keep &= stats[:, cv2.CC_STAT_TOP] + h <= row_limit
    keep[0] = False
    keep[np.unique(lab[border & hole.astype(bool)])] = False
    return keep[lab]


def seen_rim(seen: np.ndarray, res: float, depth: float, sides: bool = False) -> np.ndarray:
    """What ``seen`` marks within ``depth`` (m) of the first seen pixel from the top and from the bottom of
    each column, and with ``sides`` from the left and from the right of each row: the plane's edges as the
    views see them.

    Why: on a TSDF scan a cupboard's top rail lies on the fused box's rounded top edge, outside the plane's
    coverage and farther from it than the views' reach, so its pane ran out of the plane over the top. The
    stiles of the doors at either end lie on the box's rounded side edges the same way, and their panes ran
    out sideways (glass tuning TSDF: a white cupboard's end door, its outer stile fused only below the pane's
    middle)."""
    if sides:
        return seen_rim(seen, res, depth) | seen_rim(seen.T, res, depth).T
    r = int(round(depth / res))
    h = seen.shape[0]
    if r <= 0 or not seen.any():
        return np.zeros(seen.shape, bool)
    rows = np.arange(h)[:, None]
    cols = seen.any(0)
    top = np.where(cols, seen.argmax(0), h)
    bottom = np.where(cols, h - 1 - seen[::-1].argmax(0), -1)
    return seen & ((rows < top + r) | (rows > bottom - r))


def pane_frame_map(cov: np.ndarray, seen: np.ndarray | None, res: float, speck: float, gap: float,
                   reach: float | None = None, max_cover: float = 1.0, rim: float = 0.0,
                   rim_sides: bool = False) -> np.ndarray:
    """What may frame a pane: the plane's coverage, joined with ``seen`` (what the views see at the
    plane's depth) when given, with covered strokes and specks thinner than ``speck`` (m) taken off, then
    gaps up to ``gap`` (m) closed.

    With ``reach`` (m), only what the views see that near the coverage is joined: farther in, what stands
    right behind the glass (books on a laser scan's shelf) is seen at the plane's depth and closed panes.
    Where the coverage holds at least ``max_cover`` of what the views see (near it), the scan's surface is
    whole and the coverage alone frames panes, as it is: a laser scan holds its doors' frames, and
    there the extra panes the views' frame gave cut cells wrong.

    Why: a TSDF glass door's frame is thin and its fused surface ragged, so the coverage holds bits of it
    while the views see all of it; what stands behind the glass at the plane's depth (a shelf's front
    edge, a jar) is a thin line or a speck inside the pane, which split it or took its fill; and a rail
    the fusion broke in places let the pane run out into the open through a gap of a few centimetres."""
    out = cov.astype(np.uint8)
    if seen is not None:
        near = seen if reach is None else seen & seen_near(cov, res, reach)
        if near.any() and (cov & near).sum() >= max_cover * near.sum():
            return cov.copy()
        out |= near.astype(np.uint8)
        if rim > 0:  # a rail on the box's rounded edge: seen at the plane's depth, at the plane's edge
            out |= seen_rim(seen, res, rim, rim_sides).astype(np.uint8)
    k = int(round(speck / res)) | 1  # odd: an even kernel shifts what it keeps by a pixel
    if k >= MIN_KERNEL:
        out = cv2.morphologyEx(out, cv2.MORPH_OPEN, np.ones((k, k), np.uint8))
    k = int(round(gap / res)) | 1
    if k >= MIN_KERNEL:
        out = cv2.morphologyEx(out, cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
    return out.astype(bool)


def framed_panes(cov: np.ndarray, res: float, frame: float, cover: float, min_area: float, rounds: int = 1,
                 min_side: float = 0.0, bar: float = 0.0, min_fill: float = 0.0) -> np.ndarray:
    """``_framed_holes`` taken ``rounds`` times, each round on the coverage with the panes found so far
    filled, then closed over ``bar`` (m).

    Why: a shelf seen through a pane splits it into two holes, and the frame of each runs partly along
    the other; once one is a pane, the other is framed too. The shelf's edge (or a glazing bar) left
    between them belongs to the door as much as the panes do: a strip of another colour across the
    door would be read as a seam between two fronts."""
    out = np.zeros(cov.shape, bool)
    for _ in range(max(1, rounds)):
        new = _framed_holes(cov | out, res, frame, cover, min_area, min_side, min_fill)
        if not new.any():
            break
        out |= new
    k = int(round(bar / res))
    if k >= 1 and out.any():
        out |= cv2.morphologyEx(out.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((2 * k + 1, 2 * k + 1), np.uint8)).astype(bool)
    return out


def solid_panes(panes: np.ndarray, o: Orthophoto, mesh: TriMesh, depth: float, max_share: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """``panes`` split into glass and solid panels: a pane whose area is at least ``max_share`` covered by
    faces facing out of the plane within ``depth`` (m) of it (each face's area projected onto the plane,
    counted where its centroid falls) is a solid panel, part of the front's surface.

    Why: a raised-panel or shaker front's panel is ringed by bevels and a frame at another depth or tilt;
    when its middle is not the plane's (tilted facets of a pyramid panel, an offset over the plane's
    tolerance) it is a hole framed all round, as a glass pane is. Glass leaves no surface there (the views
    see what lies behind it), a panel leaves it all; taken for glass, the panel blocked every cut through its
    columns and a drawer bank stayed one cell. Summed projected areas read the same on fine and decimated
    meshes."""
    if not panes.any() or max_share >= 1.0:
        return panes, np.zeros(panes.shape, bool)
    n, lab = cv2.connectedComponents(panes.astype(np.uint8), connectivity=CONNECTIVITY)
    near = slab_faces(mesh, o.plane, depth, _ANY_OUTWARD_DEG)
    r, c, ok = o.pixels_of(mesh.face_centroids[near])
    projected = mesh.face_areas[near] * (mesh.face_normals[near] @ o.plane.n)
    solid = np.bincount(lab[r[ok], c[ok]], weights=projected[ok], minlength=n)
    area = np.bincount(lab.ravel(), minlength=n) * o.res ** 2
    drop = np.zeros(n, bool)
    drop[1:] = solid[1:] >= max_share * area[1:]
    return panes & ~drop[lab], drop[lab] & panes


def _framed_holes(cov: np.ndarray, res: float, frame: float, cover: float, min_area: float,
                  min_side: float = 0.0, min_fill: float = 0.0) -> np.ndarray:
    """Holes in a plane's coverage ``cov`` framed all round by the plane's surface: each hole (8-connected,
    not touching the grid's border) of at least ``min_area`` m², whose bounding box is ``min_side`` m both
    ways and at least ``min_fill`` full, and whose ``frame`` m wide band around it is covered by at least
    ``cover``.

    Why: a glass-panel door is a frame around a pane the scan mostly lacks (the sensor sees through it),
    so on its plane it is a ring; the door spans the ring and the pane. A gap between two fronts or an
    open shelf beside a front is no hole framed all round by a door-frame wide band of surface. A
    handle's scanning shadow on a TSDF front is framed all round too, but narrow or ragged; a pane is a
    rectangle cut to its frame."""
    out = np.zeros(cov.shape, bool)
    r = int(round(frame / res))
    if frame <= 0 or r < 1 or not cov.any():
        return out
    hole = (~cov).astype(np.uint8)
    n, lab, stats, _ = cv2.connectedComponentsWithStats(hole, connectivity=CONNECTIVITY)
    h, w = cov.shape
    x, y, bw, bh, area = (stats[:, k] for k in (cv2.CC_STAT_LEFT, cv2.CC_STAT_TOP, cv2.CC_STAT_WIDTH,
                                                 cv2.CC_STAT_HEIGHT, cv2.CC_STAT_AREA))
    cand = np.flatnonzero((area * res ** 2 >= min_area) & (np.minimum(bw, bh) * res >= min_side)
                      & (area >= min_fill * bw * bh) & (x > 0) & (y > 0) & (x + bw < w) & (y + bh < h))
    kern = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
    for k in cand[cand > 0]:  # label 0: the covered pixels
        y0, y1, x0, x1 = max(y[k] - r, 0), min(y[k] + bh[k] + r, h), max(x[k] - r, 0), min(x[k] + bw[k] + r, w)
        me = (lab[y0:y1, x0:x1] == k).astype(np.uint8)
        band = cv2.dilate(me, kern).astype(bool) & ~me.astype(bool)
        if band.any() and cov[y0:y1, x0:x1][band].mean() >= cover:
            out[y0:y1, x0:x1] |= me.astype(bool)
    return out


def fill_panes(o: Orthophoto, panes: np.ndarray, frame: float, gap: float) -> None:
    """Give each pane of ``panes`` the median colour of the frame around it and count it as seen, in
    place: the seen pixels between ``gap`` and ``gap + frame`` (m) from the pane.

    Why: the views see through a pane to the shelves behind it, and the plane's colour there is none;
    left unseen, the lines through a glass door hold only its rails, so the seams between doors were
    judged on a few pixels and the splitter cut doors at the panes' edges. A door's face is its frame;
    painted its colour, the pane reads as more of it. The pane's own edge is left out of the median (the
    frame's inner edge and the putty are shaded, and with them the painted pane was a darker panel whose
    outline out-scored the seams beside it)."""
    g = max(0, int(round(gap / o.res)))
    r = max(1, int(round(frame / o.res)))
    seen = o.n_views > 0
    n, lab, stats, _ = cv2.connectedComponentsWithStats(panes.astype(np.uint8), connectivity=CONNECTIVITY)
    h, w = panes.shape
    for k in range(1, n):
        x, y, bw, bh = (int(stats[k, q]) for q in (cv2.CC_STAT_LEFT, cv2.CC_STAT_TOP, cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT))
        pad = g + r + 1
        y0, y1, x0, x1 = max(y - pad, 0), min(y + bh + pad, h), max(x - pad, 0), min(x + bw + pad, w)
        me = lab[y0:y1, x0:x1] == k
        dist = cv2.distanceTransform((~me).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_3)
        band = (dist > g) & (dist <= g + r) & seen[y0:y1, x0:x1]
        if band.any():
            o.color[y0:y1, x0:x1][me] = np.median(o.color[y0:y1, x0:x1][band], axis=0)
            o.n_views[y0:y1, x0:x1][me] = max(1, int(np.median(o.n_views[y0:y1, x0:x1][band])))


def cov_outline(cov: np.ndarray, px: int) -> np.ndarray:
    """The plane's outline with holes and notches up to ``px`` wide filled: a pixel is inside when
    the plane is within ``px`` on both sides of it along a row or along a column (a handle's scanning
    shadow is a hole, or a notch where the handle sits at the front's edge; a closing misses both once
    the shadow is wider than the kernel)."""
    c = cov.astype(np.uint8)
    k = np.ones((1, px + 1), np.uint8)
    left = cv2.dilate(c, k, anchor=(px, 0), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    right = cv2.dilate(c, k, anchor=(0, 0), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    up = cv2.dilate(c, k.T, anchor=(0, px), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    down = cv2.dilate(c, k.T, anchor=(0, 0), borderType=cv2.BORDER_CONSTANT, borderValue=0)
    return cov.astype(bool) | (left & right).astype(bool) | (up & down).astype(bool)


def thin_lines(mask: np.ndarray, res: float, min_len: float, max_width: float) -> np.ndarray:
    """Pixels of ``mask`` on straight horizontal or vertical lines at least ``min_len`` long and at most
    ``max_width`` thick: the edges of a shaker door's frame and panel, tile joints, seams. They are
    structure of a front, not clutter on it (a poster or a shelf is a filled blob and stays)."""
    if min_len <= 0 or not mask.any():
        return np.zeros(mask.shape, bool)
    m = mask.astype(np.uint8)
    L = max(MIN_KERNEL, int(round(min_len / res)))
    t = max(2, int(round(max_width / res)) + 1)
    long_h = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((1, L), np.uint8))
    long_v = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((L, 1), np.uint8))
    thick_v = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((t, 1), np.uint8))  # runs across a horizontal line
    thick_h = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((1, t), np.uint8))
    return ((long_h & ~thick_v) | (long_v & ~thick_h)).astype(bool)


def protrusion_from_faces(o: Orthophoto, centroids: np.ndarray, normals: np.ndarray, hc: HandleConfig, win: float,
                   behind: float) -> np.ndarray:
    """Grid pixels under outward-facing faces standing ``hc.protrusion_depth`` in front of the plane
    (handles in the mesh), splatted by centroid (``image.surface_rays`` off), closed over ``hc.bar_close_px`` and grown by 1 px: the
    centroids of a bar's faces sit half a face inside its outline, and a 1.5 cm bar at 4 mm must not
    come out 2 px wide.

    With ``win`` > 0 (``protrusion_from_surface``) they stand ``depth`` in front of the surface
    around them instead: the median offset of the faces within ``win`` (``hc.surface_block`` blocks, each its
    faces' median), faces from ``behind`` the plane on. A TSDF wall lies a centimetre or two off its fitted
    plane in places, and its bumps there are no handles."""
    p = o.plane
    depth = hc.protrusion_depth
    dn = centroids @ p.n - p.d
    # outward faces that can stand out: against the plane, from depth[0]; against the surface, from behind it
    cand = np.flatnonzero((dn > (-behind if win > 0 else depth[0])) & (dn < depth[1]) & (normals @ p.n > hc.protrusion_min_cos))
    r, c, ok = o.pixels_of(centroids[cand])
    return _protruding(dn[cand][ok], r[ok], c[ok], o, hc, win)


def protrusion_map(o: Orthophoto, surf: PlaneSurface, hc: HandleConfig, win: float, behind: float) -> np.ndarray:
    """Grid pixels whose front-most surface (``surf.front``, facing outwards: ``hc.protrusion_min_cos``)
    stands ``hc.protrusion_depth`` in front of the plane (handles in the mesh), closed over
    ``hc.bar_close_px`` and grown by 1 px.

    With ``win`` > 0 (``protrusion_from_surface``, the default) it stands ``depth`` in front of the surface
    around it instead: the median offset of the surface within ``win`` (``hc.surface_block`` blocks, each
    its pixels' median), from ``behind`` the plane on. A TSDF wall lies a centimetre or two off its fitted
    plane in places, and its bumps there are no handles."""
    depth = hc.protrusion_depth
    dn = surf.front
    with np.errstate(invalid="ignore"):
        # outward surface that can stand out: against the plane, from depth[0]; against the surface, from behind it
        cand = (dn > (-behind if win > 0 else depth[0])) & (dn < depth[1]) & (surf.front_cos > hc.protrusion_min_cos)
    r, c = np.nonzero(cand)
    return _protruding(dn[r, c].astype(np.float64), r, c, o, hc, win)


def _protruding(dn: np.ndarray, r: np.ndarray, c: np.ndarray, o: Orthophoto, hc: HandleConfig, win: float) -> np.ndarray:
    """Grid pixels (rows ``r``, cols ``c``) whose offsets ``dn`` stand ``hc.protrusion_depth`` out, from the
    plane or (``win`` > 0) from the surface around them, closed over ``hc.bar_close_px`` and grown by 1 px."""
    h, w = o.n_views.shape
    depth, block = hc.protrusion_depth, hc.surface_block
    if win > 0:
        dn = dn - _local_surface(dn, r, c, (h, w), max(1, int(round(block / o.res))), win / block)[r, c]
    sel = (dn > depth[0]) & (dn < depth[1])
    out = np.zeros((h, w), np.uint8)
    out[r[sel], c[sel]] = 1
    out = cv2.morphologyEx(out, cv2.MORPH_CLOSE, np.ones((hc.bar_close_px, hc.bar_close_px), np.uint8))
    return cv2.dilate(out, NEIGHBOURS).astype(bool)


def _local_surface(dn: np.ndarray, r: np.ndarray, c: np.ndarray, shape: tuple[int, int], block: int,
                   win_blocks: float) -> np.ndarray:
    """Per pixel: the median over a window of ``win_blocks`` blocks (odd, >= 3) of the per-block median
    offsets ``dn`` of faces at (r, c); 0 (the plane) where fewer than a third of the window's blocks
    (inside the grid) hold faces (a bar seen with little of the surface around it stands on the plane)."""
    h, w = shape
    bh, bw = -(-h // block), -(-w // block)
    if not len(dn):
        return np.zeros(shape)
    bid = (r // block) * bw + c // block
    order = np.lexsort((dn, bid))
    cnt = np.bincount(bid, minlength=bh * bw)
    start = np.concatenate([[0], np.cumsum(cnt)[:-1]])
    coarse = np.full(bh * bw, np.nan)
    has = cnt > 0
    coarse[has] = dn[order][start[has] + cnt[has] // 2]
    coarse = coarse.reshape(bh, bw)
    k = max(MIN_KERNEL, int(round(win_blocks)) | 1)
    padded = np.pad(coarse, k // 2, constant_values=np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # windows without faces stay NaN -> 0
        win = np.lib.stride_tricks.sliding_window_view(padded, (k, k))
        local = np.nanmedian(win, axis=(-2, -1))
    inside = np.lib.stride_tricks.sliding_window_view(np.pad(np.ones(coarse.shape), k // 2), (k, k)).sum((-2, -1))
    local[np.isfinite(win).sum((-2, -1)) * _MIN_SURFACE_DIV < inside] = 0.0
    local = np.nan_to_num(local, nan=0.0)
    return np.repeat(np.repeat(local, block, 0), block, 1)[:h, :w]


def pane_frame_handles(handles: Sequence[Handle], panes: np.ndarray, bars: np.ndarray, reach_px: int,
                       share: float) -> list[Handle]:
    """``handles`` less the colour-only ones on a pane's frame (their boxes inside the pane's box, of ``panes``,
    grown by ``reach_px``) when a bar standing out of the scan (``share`` of its pixels on ``bars``) is on
    the same frame.

    Why: a glass-panel door is one front around its pane, and it has one handle. Its stiles are shaded by
    the glass beside them (a patch 4 x 14 cm a little darker than the frame, on an oven's door), and a second
    "handle" there made the splitter cut the door between the two along the pane's edge; the bar the scan
    holds is the door's. The plane-wide rule (``bars_outrank_colour`` at one bar) mended it too but cost
    held-apart parts elsewhere; a pane's frame is one door."""
    if reach_px <= 0 or not len(handles) or not panes.any():
        return list(handles)
    n, _, stats, _ = cv2.connectedComponentsWithStats(panes.astype(np.uint8), connectivity=CONNECTIVITY)
    on_bar = stand_out(handles, bars, share)
    gone: set[int] = set()
    for k in range(1, n):
        x, y, w, h = (int(stats[k, q]) for q in (cv2.CC_STAT_LEFT, cv2.CC_STAT_TOP, cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT))
        x0, y0, x1, y1 = x - reach_px, y - reach_px, x + w + reach_px, y + h + reach_px
        on = [i for i, hd in enumerate(handles)
              if hd.box[0] >= x0 and hd.box[1] >= y0 and hd.box[2] <= x1 and hd.box[3] <= y1]
        if any(on_bar[i] for i in on):
            gone.update(i for i in on if not on_bar[i])
    return [hd for i, hd in enumerate(handles) if i not in gone]


def proud_handles(layer: Orthophoto, handles: Sequence[Handle], cov: np.ndarray, outline: np.ndarray,
                  diff: np.ndarray, thr: float, cfg: HeuristicConfig) -> list[Handle]:
    """Bars read on ``layer`` (a plane's orthophoto fused ``handles.proud_layer`` in front of it, on the
    plane's grid) that a proud bar would leave: parallax smears such a bar on the plane and sharpens it in
    front, while a seam or an edge is sharpest on the plane. So a bar is kept that stands out on the layer by
    ``handles.proud_contrast`` and ``handles.proud_gain`` times more than on the plane (``diff``: the plane's
    colour distance from its background), on the plane too by its threshold ``thr`` (the floor seen past a
    plane's edge through the layer is not on the plane at all), at least ``handles.proud_margin`` inside the
    plane's coverage (nearer, the layer sees past the plane's edge), strongest first, each farther than
    ``handles.proud_near`` from every handle already kept (the same bar, found on the plane)."""
    hc = cfg.handles
    layer.n_views[~cov] = 0
    near = int(round(hc.proud_near / layer.res))
    ldiff = off_background(layer, hc)
    m = int(round(hc.proud_margin / layer.res))
    # beyond the grid counts as beyond the coverage: a plane's grid ends 2 cm past its extent
    inner = cv2.erode(cov.astype(np.uint8), np.ones((2 * m + 1, 2 * m + 1), np.uint8), borderType=cv2.BORDER_CONSTANT,
                      borderValue=0).astype(bool) if m else cov
    scored = []
    for h in find_handles(layer, cov, cfg, ldiff, None, outline, bars_only=True):
        r, c = h.pixels[:, 1], h.pixels[:, 0]
        if not inner[r, c].all():
            continue
        on_layer, on_plane = float(ldiff[r, c].mean()), float(diff[r, c].mean())
        if on_plane >= thr and on_layer >= max(hc.proud_gain * on_plane, hc.proud_contrast):
            scored.append((on_layer, h))
    boxes = [h.box for h in handles]
    out = []
    for _, h in sorted(scored, key=lambda t: -t[0]):
        x0, y0, x1, y1 = h.box
        if any(b[0] - near < x1 and x0 < b[2] + near and b[1] - near < y1 and y0 < b[3] + near for b in boxes):
            continue
        boxes.append(h.box)
        out.append(h)
    return out


def find_image_fronts(mesh: TriMesh, frames: Sequence[Frame], raster: Rasterizer, read_rgb: Callable[[Frame], np.ndarray],
                      cfg: HeuristicConfig = HeuristicConfig(), taken_faces: np.ndarray | None = None,
                      mesh_fronts: Sequence[Front] = (),
                      detect_lines: Callable[[np.ndarray], np.ndarray] | None = None) -> ImageFronts:
    """Fronts from the colour frames (see module docstring), by the rules of ``cfg``. ``taken_faces``
    (bool per face) are faces of fronts already found on the mesh: cells overlapping them are left to
    the mesh rules. ``detect_lines`` (an RGB image -> its line segments (N, 4+: x0, y0, x1, y1 px)) gives
    learned seam evidence when ``lines.enabled`` (line_evidence.py)."""
    rules, hc, clut = cfg.fronts, cfg.handles, cfg.clutter
    cams = np.array([f.c2w[:3, 3] for f in frames]) if len(frames) else np.zeros((1, XYZ))
    planes = vertical_planes(mesh, cams.mean(0), cfg.planes, max_tilt=rules.max_tilt,
                             min_area=max(cfg.planes.min_area, rules.min_w * rules.min_h))
    orthos, calib, per_view = build_orthophotos(planes, frames, raster, mesh.n_faces, read_rgb, cfg.ortho,
                                                cfg.calibration, cfg.registration, hc.proud_layer)
    supports: list[LineSupport] = []
    if cfg.lines.enabled and detect_lines is not None:
        supports = line_support(orthos, frames, raster, read_rgb, detect_lines, lambda fi: per_view.get(fi, calib), cfg)
    centroids = mesh.face_centroids
    fronts: list[Front] = []
    gridded: set[int] = set()  # fronts cut out by straight seams in a plane without tile-sized cells
    singles: set[int] = set()  # handle-less fronts cut on one side only (the others: the plane's outline)
    pieces: set[int] = set()  # handle-less fronts on the front of a piece standing free (``piece_front``)
    round_doors: set[int] = set()  # porthole doors (``portholes``): kept, and hinged at a side
    one_cut = cfg.cells.single_cut or cfg.cells.piece_max_w > 0
    veto_evidence: list[VetoEvidence] = []
    pane_regions: list[PaneRegion] = []
    for i, o in enumerate(orthos):
        # a modelled scene's fronts are a few large triangles cut apart by exact seams: the mesh rules read
        # those, and rays reading the whole of them cut panels and bevels into false cells
        rays = cfg.image.surface_rays or (coarse_faces(mesh, o.plane.faces, cfg.image.rays_face_edge)
                                          and not modelled_surface(mesh, o.plane.faces, cfg.image.modelled_share))
        if rays:
            surf = cast_surface(o.grid_points(), o.plane.n, raster, cfg.planes.offset_tol, hc.protrusion_depth[1],
                                cfg.planes.offset_tol)
            flat = flat_surface(surf.offset, o.res, cfg.planes.slope_win, cfg.planes.angle_tol_deg)
            if cfg.image.seen_reach > 0:
                flat &= seen_near(o.n_views > 0, o.res, cfg.image.seen_reach)
            cov = coverage_map(o, flat, cfg.planes.min_fragment_area, cfg.image.coverage_close)
        else:
            cov = coverage_from_faces(o, mesh, cfg.planes.min_fragment_area, cfg.image.coverage_close)
        # cells are cut on the plane's own coverage; whether a cell is covered is read with its tilted faces
        cell_cov = cov
        if not rays and cfg.image.coverage_tilt_deg > 0:
            cell_cov = coverage_from_faces(o, mesh, cfg.planes.min_fragment_area, cfg.image.coverage_close,
                                           cfg.image.coverage_tilt_depth, cfg.image.coverage_tilt_deg)
        views_at_plane = o.n_views.copy()
        seen_at_plane = views_at_plane > 0
        o.n_views[~cov] = 0  # where the plane's surface is not (floor, worktop edge seen at the same depth)
        framing = pane_frame_map(cov, seen_at_plane if cfg.image.pane_seen else None, o.res, cfg.image.pane_speck,
                                 cfg.image.pane_gap, cfg.image.pane_seen_reach, cfg.image.pane_seen_max_cover,
                                 cfg.image.pane_seen_rim, cfg.image.pane_seen_rim_sides)
        panes = framed_panes(framing, o.res, cfg.image.pane_frame, cfg.image.pane_frame_cover, cfg.image.pane_min_area,
                             cfg.image.pane_rounds, cfg.image.pane_min_side, cfg.image.pane_bar,
                             cfg.image.pane_min_fill)
        panes, solid = solid_panes(panes, o, mesh, cfg.image.pane_solid_depth, cfg.image.pane_solid_share)
        if solid.any():  # a panel's middle is the front's surface, seen in its own colours
            cov, cell_cov = cov | solid, cell_cov | solid
            o.n_views[solid] = views_at_plane[solid]
        if panes.any():
            pane_regions.append(PaneRegion.of(o, panes, cfg.image.glass_behind_grow))
            cov = cov | panes
            if cfg.image.pane_cell_cover:  # a glass door's cell is its frame and its pane, not the ring alone
                cell_cov = cell_cov | panes
            if cfg.image.pane_fill:
                fill_panes(o, panes, cfg.image.pane_frame, cfg.image.pane_edge)
        diff = off_background(o, hc)
        outline = cov_outline(cov, cfg.image.outline_fill_px)  # handle shadows are holes in the plane, not its outline
        win = hc.background_win if hc.protrusion_from_surface else 0.0
        bars = (protrusion_map(o, surf, hc, win, cfg.planes.offset_tol) if rays
                else protrusion_from_faces(o, centroids, mesh.face_normals, hc, win, cfg.planes.offset_tol))
        lone: list[Handle] = []
        held = bars & outline
        handles = find_handles(o, cov, cfg, diff, held, outline, lone=lone)
        if hc.pane_bar_reach > 0:
            handles = pane_frame_handles(handles, panes, held, int(round(hc.pane_bar_reach / o.res)), hc.bar_share)
        thr = off_threshold(diff, o.n_views > 0, cfg)
        if o.layer is not None:
            handles += proud_handles(o.layer, handles, cov, outline, diff, thr, cfg)
        veto_evidence.append(VetoEvidence(thr, _hardware(bars, handles)))
        shadows: list[Handle] = []
        if hc.shadows:  # handle-shaped holes above eye level: they type joints, they do not cut cells
            eye_row = int(np.floor((o.v_top - float(np.median(cams[:, 2]))) / o.res))  # cameras' median height
            holes = enclosed_holes(o.n_views > 0, outline, o.res, hc.shadow_min_thick, row_limit=eye_row)
            shadows = find_handles(o, cov, cfg, np.zeros_like(diff), holes, outline, bars_only=True) if holes.any() else []
        clutter = (diff > thr) & (o.n_views > 0)
        structure = thin_lines(clutter, o.res, clut.line_min_len, clut.line_max_width)
        for h in handles:  # a handle is not clutter
            structure[h.pixels[:, 1], h.pixels[:, 0]] = True
        clutter &= ~structure
        p = o.plane
        rel = centroids - p.n * p.d
        in_plane = np.stack([rel @ p.u, centroids[:, 2], rel @ p.n], 1)  # (u, z, depth) of every face, once per plane
        ports: list[tuple[int, int, int, int]] = []
        if cfg.portholes.enabled:
            # the ring stands out of the plate's plane, not of the surface around it (the ring itself)
            proud = bars if win == 0.0 else (
                protrusion_map(o, surf, hc, 0.0, cfg.planes.offset_tol) if rays
                else protrusion_from_faces(o, centroids, mesh.face_normals, hc, 0.0, cfg.planes.offset_tol))
            ports = find_portholes(proud, o.res, cfg.portholes)
        cells = split_cells(o, cov, handles, cfg, supports[i].lines(cfg.lines.min_views) if supports else None, lone,
                            panes, [porthole_core(b) for b in ports] if cfg.portholes.bar_cuts else ())
        tiled = is_tiled(cells, cov, o.res, cfg.cells)
        mine: list[Front] = []
        for cell in cells:
            f = _cell_front(o, cell, cell_cov, clutter, in_plane, cfg, None,
                            (thr, structure) if clut.cell_median else None, one_cut)
            if f is not None:
                if f.handle_points is None:
                    f.shadow_points = _shadow_in_cell(o, cell, shadows)
                    if cell.cut_sides < _MIN_CUT_SIDES:
                        singles.add(id(f))
                mine.append(f)
                if not tiled and 0 < cfg.cells.handleless_min_seams <= cell.seam_cuts:
                    gridded.add(id(f))
        # a plane that only averaged normals found may be any small panel (a chair's back, a piece's side):
        # its fronts need a handle, not only the piece standing free
        if (not tiled and not o.plane.averaged and piece_of_fronts(mine, o, cov, cfg)
                and (not cfg.cells.piece_behind or stands_in_room(mesh, o.plane, cfg.room_wall))):
            pieces.update(id(f) for f in mine)
        for box in ports:
            door = _box_front(o, box, in_plane, cfg.portholes.face_depth, cfg.image.min_faces)
            if door is None:
                continue
            mine = [f for f in mine if _overlap(f, door) < _PORTHOLE_COVERED * door.w * door.h
                    and not _plate_strip(f, door, cfg.portholes.plate_gap)]
            mine.append(door)
            round_doors.add(id(door))
        fronts += mine
    if not cfg.cells.single_cut:
        fronts = [f for f in fronts if id(f) not in singles or id(f) in pieces]
    fronts, split_mesh = _settle_with_mesh_fronts(fronts, taken_faces, mesh_fronts, mesh.n_faces, cfg.image,
                                                  gridded if cfg.cells.mesh_split_seams else set())
    # a handle-less cell is a front beside a front with a handle, or when straight seams along its whole
    # length cut it out on ``handleless_min_seams`` sides (push-to-open fronts), or in a column of
    # ``stack_min`` stacked cells of one width (a drawer pedestal with edge pulls); tiles and splash-backs
    # have no handles and, tiled, cells smaller than a front
    stacked = stacks(fronts, rules, cfg.cells.stack_min)
    fronts = plain_fronts_kept(fronts, rules, gridded, stacked, singles, pieces | round_doors)
    # ... but a handle-less panel that reaches down to the floor is wall (beside a room door, say): base
    # units stand on a plinth and room doors have handles; a stack's bottom drawer and a piece's fronts stay
    if cfg.image.plain_floor_gap > 0:
        fronts = off_the_floor(fronts, floor_height(mesh, cfg.floor), cfg.image.plain_floor_gap, stacked | pieces | round_doors)
    for f in fronts:
        hpts = f.handle_points if f.handle_points is not None and len(f.handle_points) else f.shadow_points
        f.kind, f.articulation = _joint(f, hpts, _neighbours(f, fronts, rules), rules, side_hinged=id(f) in round_doors)
    doors_in_rows(fronts, rules)
    vetoed = sorted(split_mesh | {k for k, f in enumerate(mesh_fronts) if _cluttered(f, orthos, veto_evidence, cfg)})
    return ImageFronts(fronts, vetoed, planes, orthos, calib, per_view, supports, pane_regions)


def plain_fronts_kept(fronts: list[Front], rules: FrontRulesConfig, gridded: set[int], stacked: set[int],
                      singles: set[int], pieces: set[int]) -> list[Front]:
    """The fronts kept of ``fronts``: every one with a handle; a handle-less one cut out on two or more sides
    when straight seams cut it out (``gridded``), it stands in a stack (``stacked``) or beside a front with a
    handle; one cut on a single side (``singles``: its other sides are the plane's outline) when it stands in a
    stack or beside a front kept so (same rows or same columns: the end of a row of doors, the top drawer of
    a pedestal); and every one on the front of a piece standing free (``pieces``).

    Why: a piece of furniture standing free ends where its plane ends, so its first and last fronts are cut
    by one seam only; a wall run's ends are handled by the same rule, as a row of fronts reaches its end."""
    def by_rules(f: Front) -> bool:
        return (f.handle_points is not None or id(f) in gridded or id(f) in stacked
                or any(g.handle_points is not None for g, _ in _neighbours(f, fronts, rules)))

    base = {id(f) for f in fronts if id(f) not in singles and by_rules(f)}
    row_ends = {id(f) for f in fronts if id(f) in singles and (id(f) in stacked or any(
        id(g) in base for g, _ in _neighbours(f, fronts, rules)))}
    keep = base | row_ends | pieces
    return [f for f in fronts if id(f) in keep]


def fronts_share(fronts: Sequence[Front], o: Orthophoto, cov: np.ndarray) -> float:
    """Share of a plane's coverage ``cov`` (grid of ``o``) that lies inside the rectangles of ``fronts`` on it.

    Why: a piece standing free is made of its fronts (a fridge's doors, a dishwasher's door below its
    control strip); a washing machine's porthole is no plane, so its only cell is the control strip over
    it, 0.40 x 0.22 m of a 0.6 x 0.84 m front, which alone would pass as the piece's front."""
    total = int(cov.sum())
    if total == 0:
        return 0.0
    inside = np.zeros(cov.shape, bool)
    for f in fronts:
        c0, c1 = (int(round((u - o.u0) / o.res)) for u in f.extent_u)
        r0, r1 = (int(round((o.v_top - v) / o.res)) for v in f.extent_v[::-1])
        inside[max(r0, 0):max(r1, 0), max(c0, 0):max(c1, 0)] = True
    return float((inside & cov).sum()) / total


def piece_of_fronts(fronts: Sequence[Front], o: Orthophoto, cov: np.ndarray, cfg: HeuristicConfig) -> bool:
    """Whether a plane's handle-less ``fronts`` (on coverage ``cov`` of ``o``) are the front of one piece standing
    free, as far as its picture tells: a small filled rectangle (``piece_front``), made of its fronts
    (``fronts_share``) and seen (``seen_share``); whether it stands in the room is the mesh's to tell."""
    cc = cfg.cells
    return (all(f.handle_points is None for f in fronts)
            and piece_front(cov, o.res, cc.piece_max_w, cfg.fronts.max_h, cc.piece_fill)
            and fronts_share(fronts, o, cov) >= cc.piece_front_share
            and seen_share(o, cov, cfg.image.seen_reach) >= cc.piece_seen)


def seen_share(o: Orthophoto, cov: np.ndarray, reach: float = 0.0) -> float:
    """Share of a plane's coverage ``cov`` that some view sees at the plane's depth (``o.n_views``), or lies
    within ``reach`` m of a pixel one sees (``seen_near``).

    Why: a piece's front is what one looks at; its side or back stands against a wall or behind a chair,
    where the scan may hold the panel whole (a laser scan) but the views see little of it, and a strip of
    what hides it cuts the panel into a "front" (free-standing tuning 305: a sideboard's side seen 31 %,
    307: a chest freezer's side 72 %; true pieces' fronts 94 % and more). ``reach`` gives back the outlines
    the depth-edge erosion took off every view: a glass door's frame is a 10 cm strip between depth edges,
    seen by no view at the plane's depth over most of it (a two-door glass cabinet: 39 % of its frames)."""
    total = int(cov.sum())
    return float((seen_near(o.n_views > 0, o.res, reach) & cov).sum()) / total if total else 0.0


def is_tiled(cells: Sequence[Cell], cov: np.ndarray, res: float, cc: CellConfig) -> bool:
    """Whether a plane's ``cells`` (on its coverage ``cov``, ``res`` m per px) are a tiling: at least
    ``cc.min_tiles`` covered cells smaller than ``cc.min_tile_side`` both ways. A tiled wall's seams cut many
    such cells, and then no handle-less cell there is a front by its seams or as a piece's front.

    Why a count: an appliance's control strip (a dishwasher's, a washing machine's) is cut at its display
    or buttons into one or two tile-sized cells above the door, and one such cell made the whole front a
    tiling (the dishwasher drop doors of free-standing tuning 308 and 309 were lost).
    A strip at most ``cc.edge_strip`` tall along the top or bottom of the coverage counts as no tile
    (``cc.tile_edge_strips`` off): a plinth or cornice cut into pieces by the seams of the fronts above it
    is no tiled wall (a TSDF wardrobe's plinth, cut in four by its door seams, left every handle-less
    front of the wardrobe to the neighbour rules)."""
    rows = np.flatnonzero(cov.any(1))
    top, bottom = (int(rows[0]), int(rows[-1]) + 1) if len(rows) else (0, 0)
    strip, near = cc.edge_strip / res, max(1, int(round(_EDGE_NEAR / res)))

    def edge(c: Cell) -> bool:
        return (not cc.tile_edge_strips and c.r1 - c.r0 <= strip
                and (c.r0 - top <= near or bottom - c.r1 <= near))

    n = sum(max(c.c1 - c.c0, c.r1 - c.r0) * res < cc.min_tile_side and not edge(c)
            and cov[c.r0:c.r1, c.c0:c.c1].mean() >= cc.min_seen for c in cells)
    return n >= max(cc.min_tiles, 1)


def stands_in_room(mesh: TriMesh, plane: Plane, rw: RoomWallConfig) -> bool:
    """Whether scan surface lies behind ``plane`` as behind anything standing in the room (``rw.behind_share``
    of the scan more than ``rw.depth`` behind it; ``planes.share_behind``): a piece's carcass and the room
    around it do, an outer wall's stretch seen between furniture has nothing behind it."""
    return share_behind(mesh, plane.n, plane.d, rw.depth, rw.wall_back, rw.plane_min_cos) >= rw.behind_share


def piece_front(cov: np.ndarray, res: float, max_w: float, max_h: float, fill: float) -> bool:
    """Whether a plane's coverage ``cov`` (grid pixels of ``res`` m) is the front of one piece standing free:
    its covered box at most ``max_w`` wide (0: never) and ``max_h`` tall, the surface filling ``fill`` of it.
    A wall is wider, or, behind furniture, a box with holes."""
    rows, cols = np.nonzero(cov)
    if max_w <= 0 or not len(rows):
        return False
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    return bool((c1 - c0) * res <= max_w and (r1 - r0) * res <= max_h and cov[r0:r1, c0:c1].mean() >= fill)


def stacks(fronts: list[Front], rules: FrontRulesConfig, n: int) -> set[int]:
    """Ids of the fronts in a column of at least ``n`` (0: none) fronts stacked one on another, each of
    the same width as the next and touching it (``_neighbours`` above/below): a drawer pedestal, a chest
    or a filing cabinet whose drawers have edge pulls or none. A wall is not cut into such a column of
    drawer-sized cells; its cells are wall-wide or door-tall."""
    if n <= 0:
        return set()
    column = nx.Graph()
    column.add_nodes_from(id(f) for f in fronts)
    column.add_edges_from((id(f), id(g)) for f in fronts for g, side in _neighbours(f, fronts, rules) if side == "vertical")
    return {k for group in nx.connected_components(column) if len(group) >= n for k in group}


def _shadow_in_cell(o: Orthophoto, cell: Cell, shadows: Sequence[Handle]) -> np.ndarray | None:
    """World points of the largest handle shadow whose box centre lies in ``cell`` (None: no shadow)."""
    inside = [h for h in shadows if cell.c0 <= 0.5 * (h.box[0] + h.box[2]) < cell.c1 and cell.r0 <= 0.5 * (h.box[1] + h.box[3]) < cell.r1]
    if not inside:
        return None
    h = max(inside, key=lambda hd: len(hd.pixels))
    return o.plane.to_world(*o.to_uv(h.pixels[:, 0], h.pixels[:, 1]))


def _settle_with_mesh_fronts(fronts: list[Front], taken: np.ndarray | None, mesh_fronts: Sequence[Front],
                             n_faces: int, p: ImageConfig, seamed: set[int] | frozenset[int] = frozenset()) -> tuple[list[Front], set[int]]:
    """Image fronts beside the fronts found on the mesh. A mesh front holding two or more image fronts
    with handles, or cut out by straight seams (ids in ``seamed``), is several fronts the mesh could not
    tell apart (a TSDF dresser is one facet; a laser scan's seam between two drawers of a chest may be
    too narrow for the mesh rules, while the photos show it): it is replaced by them. Otherwise the mesh front stands: an image front lying mostly (> ``mesh_share``) on
    its faces is dropped, and one touching it loses those faces (it keeps ``min_faces`` or goes). Returns
    the kept image fronts and the indices of the mesh fronts replaced."""
    if taken is None or not taken.any():
        return fronts, set()
    owner = np.full(n_faces, -1, np.int64)
    for k, mf in enumerate(mesh_fronts):
        owner[mf.faces] = k
    held: dict[int, int] = {}
    for f in fronts:
        o = owner[f.faces]
        if (f.handle_points is not None or id(f) in seamed) and len(o):
            k = int(np.bincount(o + 1).argmax()) - 1
            if k >= 0 and (o == k).mean() > 0.5:
                held[k] = held.get(k, 0) + 1
    split = {k for k, n in held.items() if n >= 2}
    standing = taken.copy()
    for k in split:
        standing[mesh_fronts[k].faces] = False
    kept = []
    for f in fronts:
        on = standing[f.faces]
        if on.sum() > p.mesh_share * max(len(f.faces), 1):
            continue
        f.faces = f.faces[~on]
        if len(f.faces) >= p.min_faces:
            kept.append(f)
    return kept, split


@dataclass
class VetoEvidence:
    """What the mesh-front veto (``_cluttered``) reads off one orthophoto besides its colours: the plane's
    off-background threshold (``off_threshold``: raised on wood grain) and its hardware, the pixels of the
    handles found and of the surface standing out of the plane (handles in the mesh)."""

    threshold: float
    hardware: np.ndarray  # bool per grid pixel


def _hardware(bars: np.ndarray, handles: Sequence[Handle]) -> np.ndarray:
    """Pixels of ``handles`` and of the surface standing out of the plane (``bars``). A front's own handle is
    no clutter: a 0.3 x 0.03 m bar fills an eighth of a 0.4 x 0.18 m drawer, which with a few off pixels
    along its edges passed ``clutter.max_share`` and the drawer was vetoed (clean kitchen 101); a bar longer
    than any handle (a scene-synthesizer drawer's 0.8 m rail) is not found as a handle, but stands out of
    the front in the scan."""
    out = bars.astype(bool).copy()
    for h in handles:
        out[h.pixels[:, 1], h.pixels[:, 0]] = True
    return out


def _cluttered(f: Front, orthos: Sequence[Orthophoto], evidence: Sequence[VetoEvidence], cfg: HeuristicConfig) -> bool:
    """A mesh front whose picture is cluttered (a tiled wall with a socket "handle") is not a front: more
    than ``clutter.max_share`` of the seen pixels of its rectangle, in the orthophoto of its plane, are off
    their local background by the plane's threshold (``evidence``), hardware left out (``image.veto_*``:
    which plane, how much seen).

    The background is taken inside the rectangle only (mirrored at its edges), as the front's own: the
    orthophoto's 12 cm median reaches over a small front's outline into the frame or the neighbours around
    it (or the plane's median colour filled into unseen pixels beside it), and every pixel near its
    corners came out off (scene-synthesizer drawers 0.25 x 0.15 m in a frame: 18-68 % off). The threshold
    is the plane's, as for handles and cells: on wood grain every pixel deviates by the fixed contrast."""
    im = cfg.image
    for o, ev in zip(orthos, evidence):
        p = o.plane
        if np.dot(p.n, f.n_out) < cfg.fronts.parallel_cos or abs(float(f.center @ p.n) - p.d) > im.veto_plane_offset:
            continue
        h, w = o.n_views.shape
        c0, c1 = int((f.extent_u[0] - o.u0) / o.res), int(np.ceil((f.extent_u[1] - o.u0) / o.res))
        r0, r1 = int((o.v_top - f.extent_v[1]) / o.res), int(np.ceil((o.v_top - f.extent_v[0]) / o.res))
        c0, c1, r0, r1 = max(c0, 0), min(c1, w), max(r0, 0), min(r1, h)
        if c1 - c0 < im.veto_min_px or r1 - r0 < im.veto_min_px:
            continue
        seen = o.n_views[r0:r1, c0:c1] > 0
        if seen.sum() < im.veto_min_seen * seen.size:
            continue
        diff = off_local(o.color[r0:r1, c0:c1], seen, o.res, cfg.handles)
        off = (diff > ev.threshold) & seen & ~ev.hardware[r0:r1, c0:c1]
        return bool(off.sum() > cfg.clutter.max_share * seen.sum())
    return False


def _clutter_share(o: Orthophoto, cell: Cell, clutter: np.ndarray, seen: np.ndarray,
                   plain: tuple[float, np.ndarray] | None, min_px: int) -> float:
    """Share of a cell's seen pixels that are clutter: off their local background (``clutter``), unless
    they are close to the cell's own median colour (``plain`` = (threshold, structure pixels to leave
    out); judged so on ``min_px`` such pixels at least). The local background is a 12 cm median, which on a front beside a front of another colour
    (or a dark gap) takes the neighbour's colour in a band along every edge; the cell's own median
    does not, while a poster or a shelf still differs from the wall around it."""
    sl = (slice(cell.r0, cell.r1), slice(cell.c0, cell.c1))
    share = float(clutter[sl][seen].mean())
    if plain is None:
        return share
    thr, structure = plain
    keep = seen & ~structure[sl]
    if keep.sum() < min_px:
        return share
    col = o.color[sl]
    med = np.median(col[keep], axis=0)
    off = np.linalg.norm(col - med, axis=-1) > thr
    return min(share, float(off[keep].mean()))


def _inner(shape: tuple[int, ...], rim: int) -> np.ndarray:
    """A cell's pixels farther than ``rim`` px from its edges (all of them where the cell is too small)."""
    m = np.zeros(shape[:2], bool)
    if 2 * rim >= min(shape[:2]):
        m[:] = True
    else:
        m[rim:shape[0] - rim, rim:shape[1] - rim] = True
    return m


def _inside_rim(cell: Cell, h: Handle, rim: int) -> bool:
    """Whether handle ``h``'s centre lies farther than ``rim`` px inside ``cell``'s edges (a front's grip
    sits on its face, not on the seam or the floor line along its edge)."""
    x, y = h.center
    return cell.c0 + rim <= x < cell.c1 - rim and cell.r0 + rim <= y < cell.r1 - rim


def _cell_front(o: Orthophoto, cell: Cell, cov: np.ndarray, clutter: np.ndarray, in_plane: np.ndarray,
                cfg: HeuristicConfig, taken: np.ndarray | None,
                plain: tuple[float, np.ndarray] | None = None, one_cut: bool = False) -> Front | None:
    """The front of one cell, or None when the cell is not door/drawer-like. A handle-less cell needs cuts
    on two sides, or with ``one_cut`` on one (kept later only by ``plain_fronts_kept``'s rules)."""
    rules, clut = cfg.fronts, cfg.clutter
    sub = cov[cell.r0:cell.r1, cell.c0:cell.c1]
    if sub.size == 0:
        return None
    rim = int(round(clut.handle_rim / o.res))
    # a front cut out by seams, its grip on its face: its own rim holds the seams, a raised panel's bevel ring
    # and a neighbour's colour, and on a fused scan the grooves and bevels the surface leaves
    inner = (_inner(sub.shape, rim) if cell.handles and cell.cut_sides >= _MIN_CUT_SIDES
             and all(_inside_rim(cell, h, rim) for h in cell.handles) else None)
    if (sub[inner] if inner is not None and cfg.cells.seen_rim else sub).mean() < cfg.cells.min_seen:
        return None
    seen = o.n_views[cell.r0:cell.r1, cell.c0:cell.c1] > 0
    limit = max(clut.max_share, clut.max_share_handle) if cell.handles else clut.max_share
    if inner is not None:
        seen = seen & inner
    if seen.any() and _clutter_share(o, cell, clutter, seen, plain, clut.median_min_px) > limit:
        return None  # posters, tiles, shelves: a front is a plain panel
    rows, cols = np.nonzero(sub)
    c0, c1 = cell.c0 + cols.min(), cell.c0 + cols.max() + 1   # tighten to the covered area
    r0, r1 = cell.r0 + rows.min(), cell.r0 + rows.max() + 1
    u_a, u_b = o.u0 + c0 * o.res, o.u0 + c1 * o.res
    v_a, v_b = o.v_top - r1 * o.res, o.v_top - r0 * o.res
    w, h = u_b - u_a, v_b - v_a
    if not (rules.min_w <= w <= rules.max_w and rules.min_h <= h <= rules.max_h):
        return None
    if not cell.handles and (cell.cut_sides < (1 if one_cut else _MIN_CUT_SIDES) or max(w, h) < cfg.cells.min_tile_side):
        return None  # a plain panel or a tile: not openable by these rules
    p = o.plane
    du, dv, dn = in_plane[:, 0], in_plane[:, 1], in_plane[:, 2]
    inside = ((du > u_a) & (du < u_b) & (dv > v_a) & (dv < v_b)
              & (dn > cfg.image.face_depth[0]) & (dn < cfg.image.face_depth[1]))
    if taken is not None:
        if taken[inside].sum() > cfg.image.mesh_share * max(inside.sum(), 1):
            return None
        inside &= ~taken
    faces = np.flatnonzero(inside)
    if len(faces) < cfg.image.min_faces:
        return None
    center = p.to_world(0.5 * (u_a + u_b), 0.5 * (v_a + v_b))
    hp = [p.to_world(*o.to_uv(hd.pixels[:, 0], hd.pixels[:, 1])) for hd in cell.handles]
    f = Front(facet=-1, handle_facets=[], center=center, n_out=p.n.copy(), u=p.u.copy(),
              extent_u=(float(u_a), float(u_b)), extent_v=(float(v_a), float(v_b)), faces=faces)
    f.handle_points = np.concatenate(hp) if hp else None
    return f


def _box_front(o: Orthophoto, box: tuple[int, int, int, int], in_plane: np.ndarray, depth: tuple[float, float],
               min_faces: int) -> Front | None:
    """The front over grid box ``box`` (r0, r1, c0, c1) of ``o``'s plane: the faces whose (u, z, depth)
    ``in_plane`` lie inside it and within ``depth`` of the plane; None with fewer than ``min_faces``."""
    r0, r1, c0, c1 = box
    p = o.plane
    u_a, u_b = o.u0 + c0 * o.res, o.u0 + c1 * o.res
    v_a, v_b = o.v_top - r1 * o.res, o.v_top - r0 * o.res
    du, dv, dn = in_plane[:, 0], in_plane[:, 1], in_plane[:, 2]
    faces = np.flatnonzero((du > u_a) & (du < u_b) & (dv > v_a) & (dv < v_b) & (dn > depth[0]) & (dn < depth[1]))
    if len(faces) < min_faces:
        return None
    center = p.to_world(0.5 * (u_a + u_b), 0.5 * (v_a + v_b))
    return Front(facet=-1, handle_facets=[], center=center, n_out=p.n.copy(), u=p.u.copy(),
                 extent_u=(float(u_a), float(u_b)), extent_v=(float(v_a), float(v_b)), faces=faces)


def _overlap(f: Front, g: Front) -> float:
    """Area (m^2) where the rectangles of coplanar fronts ``f`` and ``g`` overlap, measured along ``g``'s axes."""
    ov = min(f.extent_v[1], g.extent_v[1]) - max(f.extent_v[0], g.extent_v[0])
    return max(u_overlap(g, f), 0.0) * max(ov, 0.0)


def _plate_strip(f: Front, door: Front, gap: float) -> bool:
    """``f`` is a strip of the plate around porthole ``door``: within ``gap`` above or below it, and at least
    as wide as the door (``_PORTHOLE_SPAN`` of it) or, over the door's columns, with no handle. A drawer
    beside the porthole (detergent) is narrower and has its grip; the plate's strips between seams and the
    control panel are not fronts, whatever its knob and the drawer's edge read as (a handle: free-standing
    tuning 311), and the panel beside the drawer, cut from it at the drawer's side, has no handle."""
    span = u_overlap(door, f)
    apart = max(f.extent_v[0] - door.extent_v[1], door.extent_v[0] - f.extent_v[1])
    plain = f.handle_points is None or not len(f.handle_points)
    return (span >= _PORTHOLE_SPAN * door.w or (plain and span > 0)) and -_PORTHOLE_SPAN * door.h < apart <= gap
