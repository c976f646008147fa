"""Surfaces the depth sensor missed: slabs over vertical planes the scan mesh lacks but the views show.

ToF and structured-light sensors return no depth on black and glossy fronts, so a fused scan has holes
where such fronts are, and every later stage works on mesh faces: a front the mesh lacks could never
become a part. Here space is carved on a voxel grid from the views: a voxel looked at through pixels
without a depth reading is *missed*, one seen in front of a reading is *free*; voxels missed by enough
views and almost never free form the volumes the sensor missed. Those volumes reach well in front of the
true surface where few views look obliquely, so they do not place it: the scan's own sparse returns on a
dark front do (small islands of surface, unlike walls and floors). Vertical planes are fitted to the
returns inside the volumes, each plane's region is the volume's section near its returns, layers of one
surface (face, handles, worktop edge) are merged, regions are trimmed to what some view sees first
through a pixel without reading, and each becomes a flat slab coloured from the views, appended to the
mesh. The original vertices and faces keep their ids (ground truth indexes them). Perception then finds
fronts on the slab as on any other plane.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import NamedTuple

import cv2
import numpy as np
from scipy import ndimage

from ..config.scene_io import MissedSurfaceConfig
from ..data.frames import Frame, SceneInput
from ..data.mesh import TriMesh
from ..raster import Rasterizer

_UP = np.array([0.0, 0.0, 1.0])
_VERTICAL_NZ = 0.3  # a face is vertical (a wall's) when its normal's vertical part is under this
_AXIS_REFINE_DEG = 2.0  # the walls' azimuth: the area-weighted mean of the faces this close to the histogram's peak
COMPLETION_VERSION = "3"  # what a completed mesh in the cache was made by


@dataclass
class HoleView:
    """One view at the working width: K, world-to-camera, the scan's z-depth render (0: no surface) and
    where the frame's own depth has a reading (None: the frame has no depth)."""

    K: np.ndarray
    w2c: np.ndarray
    render_z: np.ndarray
    reading_z: np.ndarray | None


@dataclass
class MissedPlane:
    """A vertical plane the sensor missed: ``point`` on it, unit ``normal`` towards the cameras, in-plane
    horizontal ``u``; ``cells`` (rows from the top, columns along ``u``) of ``res`` m from ``(u0, v_top)``."""

    point: np.ndarray
    normal: np.ndarray
    u: np.ndarray
    u0: float
    v_top: float
    res: float
    cells: np.ndarray
    n_returns: int = 0
    returns: np.ndarray | None = None  # the scan returns (N, 3) that fixed the plane

    @property
    def area(self) -> float:
        return float(self.cells.sum()) * self.res ** 2


def hole_views(frames: Sequence[Frame], raster: Rasterizer, cfg: MissedSurfaceConfig) -> list[HoleView]:
    """Evenly chosen views (at most ``cfg.max_views``) at ``cfg.work_width`` px with their renders and depth readings."""
    from .images import frame_depth

    idx = np.unique(np.linspace(0, len(frames) - 1, min(cfg.max_views, len(frames))).round().astype(int)) if frames else []
    out = []
    for i in idx:
        f = frames[int(i)]
        w = min(cfg.work_width, f.intrinsics.width)
        intr = f.intrinsics.scaled(w, max(1, round(f.intrinsics.height * w / f.intrinsics.width)))
        r = raster.render(intr.K, f.c2w, intr.width, intr.height)
        reading = None
        if f.depth is not None:
            d = frame_depth(f)
            if d is not None:
                reading = cv2.resize(np.nan_to_num(d.astype(np.float32), nan=0.0), (intr.width, intr.height),
                                     interpolation=cv2.INTER_NEAREST)
        out.append(HoleView(intr.K, f.w2c, r.depth, reading))
    return out


def hole_share(views: Sequence[HoleView]) -> float:
    """Mean share of the views' pixels without a depth reading (a view without depth: without scan surface).
    Sensors that miss dark surfaces leave many; a scan without them few (out of range, grazing, edges)."""
    if not views:
        return 0.0
    return float(np.mean([((v.reading_z if v.reading_z is not None else v.render_z) <= 0).mean() for v in views]))


def carve(views: Sequence[HoleView], lo: np.ndarray, shape: tuple[int, int, int], cfg: MissedSurfaceConfig) -> np.ndarray:
    """Voxels (grid from ``lo``, side ``cfg.voxel_m``) the sensor missed: seen through hole pixels in at least
    ``cfg.min_views`` views and in front of a scan surface or a depth reading in at most ``cfg.max_free``.
    A voxel is dropped as soon as it is seen free too often or can no longer gather enough hole views
    (most of a room's air after a few views), so later views project only what is left."""
    n = int(np.prod(shape))
    alive = np.arange(n, dtype=np.int64)
    centres_all = (lo + (np.stack(np.unravel_index(alive, shape), 1) + 0.5) * cfg.voxel_m).astype(np.float32)
    missed = np.zeros(n, np.int16)
    free = np.zeros(n, np.int16)
    margin = cfg.margin_m
    for left, v in zip(range(len(views) - 1, -1, -1), views):
        centres = centres_all[alive] if len(alive) < n else centres_all
        h, w = v.render_z.shape
        pc = centres @ v.w2c[:3, :3].T.astype(np.float32) + v.w2c[:3, 3].astype(np.float32)
        z = pc[:, 2]
        ok = z > cfg.near_m
        zi = np.where(ok, z, np.float32(1.0))
        px = np.floor(np.float32(v.K[0, 0]) * pc[:, 0] / zi + np.float32(v.K[0, 2] + 0.5)).astype(np.int32)
        py = np.floor(np.float32(v.K[1, 1]) * pc[:, 1] / zi + np.float32(v.K[1, 2] + 0.5)).astype(np.int32)
        ok &= (px >= 0) & (px < w) & (py >= 0) & (py < h)
        sel = np.flatnonzero(ok)
        rz = v.render_z[py[sel], px[sel]]
        zs = z[sel]
        hit = rz > 0
        behind_scan = hit & (zs > rz + margin)  # hidden by the scan's surface: this view says nothing
        if v.reading_z is None:
            is_free = hit & (zs < rz - margin)
            hole = ~hit
        else:
            # the sensor's own reading decides: where it read nothing, the scan surface a ray reaches
            # (a floor behind a black chest) was not what the camera saw there
            dz = v.reading_z[py[sel], px[sel]]
            read = dz > 0
            is_free = read & (zs < dz - margin)
            hole = ~read & ~behind_scan
        free[alive[sel[is_free]]] += 1
        missed[alive[sel[hole]]] += 1
        alive = alive[(free[alive] <= cfg.max_free) & (missed[alive] + left >= cfg.min_views)]
    out = np.zeros(n, bool)
    out[alive] = missed[alive] >= cfg.min_views
    return out.reshape(shape)


def island_vertices(mesh: TriMesh, max_area: float, pieces: np.ndarray | None = None) -> np.ndarray:
    """Vertices of mesh pieces (connected through shared vertices) under ``max_area`` m²: a missed surface keeps
    only islands of returns, while the walls and floor around it are large connected surfaces. ``pieces``: the
    vertices' piece labels when already computed (``_pieces``)."""
    lab = _pieces(mesh) if pieces is None else pieces
    area = np.bincount(lab[mesh.faces[:, 0]], weights=mesh.face_areas, minlength=lab.max() + 1)
    return area[lab] < max_area


def flat_vertices(mesh: TriMesh, min_nz: float, pieces: np.ndarray | None = None) -> np.ndarray:
    """Vertices of mesh pieces facing up or down: the area-weighted mean of their faces' normals has a vertical
    part of at least ``min_nz`` (1: none). Such a piece is a worktop's or a shelf's return, not a front's.
    ``pieces`` as for ``island_vertices``."""
    if min_nz >= 1.0:
        return np.zeros(mesh.n_vertices, bool)
    lab = _pieces(mesh) if pieces is None else pieces
    piece = lab[mesh.faces[:, 0]]
    area = np.bincount(piece, weights=mesh.face_areas, minlength=lab.max() + 1)
    nz = np.bincount(piece, weights=mesh.face_areas * mesh.face_normals[:, 2], minlength=lab.max() + 1)
    return (np.abs(nz) >= min_nz * np.maximum(area, 1e-12))[lab]


def _pieces(mesh: TriMesh) -> np.ndarray:
    """Connected piece label of every vertex (connected through shared vertices)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = mesh.faces
    n = mesh.n_vertices
    rows = np.concatenate([f[:, 0], f[:, 1]])
    cols = np.concatenate([f[:, 1], f[:, 2]])
    return connected_components(coo_matrix((np.ones(len(rows), np.int8), (rows, cols)), shape=(n, n)), directed=False)[1]


class FittedPlane(NamedTuple):
    """A vertical plane through scan returns: ``point``, unit ``normal`` towards the cameras, the ``inliers``
    (indices into the returns) and whether they are a ``line`` (spread across only, not up)."""

    point: np.ndarray
    normal: np.ndarray
    inliers: np.ndarray
    line: bool = False


def fit_vertical_planes(pts: np.ndarray, cameras: np.ndarray, cfg: MissedSurfaceConfig, rng: np.random.Generator,
                        need: int, tol: float, axis_deg: float | None = None) -> list[FittedPlane]:
    """Vertical planes through scan returns (RANSAC: two nearby returns and the vertical fix a plane; the
    returns' own normals are no help, a few-triangle island has any), oriented towards the cameras, while a
    plane gathers ``need`` returns within ``tol`` m. A plane most cameras stand behind, or whose inliers do
    not spread over ``cfg.min_spread_m`` both across and up, is not a surface seen and is skipped; unless
    its inliers run at least ``cfg.min_line_m`` across (a horizontal line of returns: a dark base run's top
    edge), is an edge (``_edge_line``) and runs along the room's axes (``axis_deg``, the walls' azimuth
    modulo 90, within ``cfg.line_axis_deg``; None: not tested), which is kept as a ``line``."""
    from scipy.spatial import cKDTree

    todo = np.arange(len(pts))
    out: list[FittedPlane] = []
    cam_c = cameras.mean(0)
    while len(todo) >= need:
        P = pts[todo]
        a = rng.integers(0, len(P), cfg.ransac_iters)
        if cfg.pair_reach_m > 0:  # a partner anywhere within reach across: columns of returns are no hypotheses
            reach = cKDTree(P[:, :2]).query_ball_point(P[a, :2], cfg.pair_reach_m)
            b = np.array([r[int(x * len(r))] for r, x in zip(reach, rng.random(len(a)))], np.int64)
        else:
            k = min(cfg.ransac_neighbours, len(P))
            _, nb_idx = cKDTree(P).query(P[a], k=k)
            b = np.asarray(nb_idx).reshape(len(a), -1)[np.arange(len(a)), rng.integers(0, k, len(a))]
        d = (P[b] - P[a]) * np.array([1.0, 1.0, 0.0])
        n = np.cross(d, _UP)
        nn = np.linalg.norm(n, axis=1)
        good = nn > cfg.voxel_m
        if not good.any():
            break
        n = n[good] / nn[good, None]
        p0 = P[a[good]]
        n *= np.where(np.einsum("ij,ij->i", cam_c - p0, n) < 0, -1.0, 1.0)[:, None]
        scores = np.zeros(len(n), np.int64)
        for i in range(0, len(n), 32):  # plane batches: (32, points) at a time
            sd = np.einsum("kij,kj->ki", P[None] - p0[i:i + 32, None], n[i:i + 32])
            scores[i:i + 32] = (np.abs(sd) <= tol).sum(1)
        best = int(np.argmax(scores))
        if scores[best] < need:
            break
        nb, pb = n[best], p0[best]
        for _ in range(cfg.refits):  # refit to the inliers: the horizontal line through them (least squares)
            inl = _one_piece(P, np.abs((P - pb) @ nb) <= tol, nb, cfg.return_reach_m)
            q = P[inl, :2] - P[inl, :2].mean(0)
            line = np.linalg.svd(q, full_matrices=False)[2][0]
            n2 = np.array([-line[1], line[0], 0.0])
            nb = n2 if n2 @ nb >= 0 else -n2
            pb = np.array([*P[inl, :2].mean(0), P[inl, 2].mean()])
        inl = _one_piece(P, np.abs((P - pb) @ nb) <= tol, nb, cfg.return_reach_m)
        u = np.cross(_UP, nb)
        span = np.percentile(np.stack([P[inl] @ u, P[inl, 2]], 1), [10, 90], axis=0)
        spread = span[1] - span[0]
        if (np.einsum("ij,j->i", cameras - pb, nb) > 0).mean() >= cfg.min_camera_share:
            if np.all(spread >= cfg.min_spread_m):
                out.append(FittedPlane(pb, nb, todo[inl]))
            elif (cfg.min_line_m > 0 and spread[0] >= cfg.min_line_m and _on_axis(nb, axis_deg, cfg.line_axis_deg)
                  and _edge_line(pts, P[inl], pb, nb, u, tol, cfg)):
                out.append(FittedPlane(pb, nb, todo[inl], line=True))
        todo = todo[~inl]
    return out


def _edge_line(pts: np.ndarray, line: np.ndarray, point: np.ndarray, normal: np.ndarray, u: np.ndarray, tol: float,
               cfg: MissedSurfaceConfig) -> bool:
    """Is a line of returns an edge, not a strip of a horizontal sheet of them: at most ``cfg.line_ahead_share``
    as many returns lie from ``cfg.line_gap_m`` to ``cfg.line_clear_m`` in front of it (towards the cameras),
    at its height and along its length? A vertical plane cuts a strip out of a dark worktop's or floor's
    returns at any angle; a worktop's front edge has nothing in front of it. The gap: the densest strip the
    plane's tolerance holds may lie a few centimetres behind the edge itself."""
    sd = (pts - point) @ normal
    a = line @ u
    z = line[:, 2]
    ahead = ((sd > cfg.line_gap_m) & (sd <= cfg.line_clear_m) & (pts[:, 2] >= z.min() - tol) & (pts[:, 2] <= z.max() + tol)
             & (pts @ u >= a.min()) & (pts @ u <= a.max()))
    if ahead.sum() > cfg.line_ahead_share * len(line):
        return False
    bins = np.floor((a - a.min()) / cfg.voxel_m).astype(int)  # a line is dense along its length: floor speckle is not
    return bool(len(np.unique(bins)) >= cfg.line_fill * (bins.max() + 1))


def room_axis_deg(mesh: TriMesh, pieces: np.ndarray, max_island_m2: float) -> float | None:
    """Azimuth (degrees, modulo 90) of the room's walls: the peak of the area-weighted azimuths of the vertical
    faces of the scan's large pieces (walls, scanned furniture); None without such faces."""
    lab_area = np.bincount(pieces[mesh.faces[:, 0]], weights=mesh.face_areas, minlength=pieces.max() + 1)
    n = mesh.face_normals
    big = (lab_area[pieces[mesh.faces[:, 0]]] >= max_island_m2) & (np.abs(n[:, 2]) < _VERTICAL_NZ)
    if not big.any():
        return None
    az = np.degrees(np.arctan2(n[big, 1], n[big, 0])) % 90.0
    hist = np.bincount(np.floor(az).astype(int) % 90, weights=mesh.face_areas[big], minlength=90)
    smooth = hist + np.roll(hist, 1) + np.roll(hist, -1)  # a wall at 0.5 degrees splits over two bins
    peak = float(np.argmax(smooth)) + 0.5
    d = (az - peak + 45.0) % 90.0 - 45.0  # signed, modulo 90
    near = np.abs(d) <= _AXIS_REFINE_DEG
    return float((peak + np.average(d[near], weights=mesh.face_areas[big][near])) % 90.0)


def _on_axis(normal: np.ndarray, axis_deg: float | None, tol_deg: float) -> bool:
    """Does a horizontal ``normal`` face along the room's axes (within ``tol_deg``); True when the axes are unknown."""
    if axis_deg is None:
        return True
    d = (np.degrees(np.arctan2(normal[1], normal[0])) - axis_deg) % 90.0
    return bool(min(d, 90.0 - d) <= tol_deg)


def _one_piece(P: np.ndarray, inl: np.ndarray, normal: np.ndarray, gap: float) -> np.ndarray:
    """The inliers of a plane that form its largest piece, returns no more than ``gap`` m apart along it (a
    plane runs on through the room and picks up returns of other surfaces it crosses)."""
    idx = np.flatnonzero(inl)
    if len(idx) < 2:
        return inl
    u = np.cross(_UP, normal)
    uv = np.stack([P[idx] @ u, P[idx, 2]], 1)
    cell = max(gap / 2, 1e-3)
    g = np.floor((uv - uv.min(0)) / cell).astype(int)
    grid = np.zeros(g.max(0) + 1, bool)
    grid[g[:, 0], g[:, 1]] = True
    lab, n = ndimage.label(ndimage.binary_dilation(grid, iterations=1), structure=np.ones((3, 3)))
    if n <= 1:
        return inl
    pl = lab[g[:, 0], g[:, 1]]
    out = np.zeros_like(inl)
    out[idx[pl == np.bincount(pl).argmax()]] = True
    return out


def plane_cells(pts: np.ndarray, point: np.ndarray, normal: np.ndarray, cfg: MissedSurfaceConfig,
                splat: float | None = None) -> MissedPlane | None:
    """The plane's missed region rasterised at ``cfg.res_m``: footprints of ``splat`` m (default: a voxel)
    around ``pts`` splatted, gaps up to ``cfg.close_m`` closed, holes filled, pieces under ``cfg.min_area``
    dropped (None: nothing left)."""
    u = np.cross(_UP, normal)
    u /= np.linalg.norm(u)
    a, z = (pts - point) @ u, pts[:, 2]
    res = cfg.res_m
    size = cfg.voxel_m if splat is None else splat
    half = size / 2
    kc = max(1, int(round(cfg.close_m / res))) | 1
    pad = kc * res  # room for the closing at the region's edges
    u0, v_top = float(a.min() - half - pad), float(z.max() + half + pad)
    w = int(np.ceil((a.max() + half + pad - u0) / res)) + 1
    h = int(np.ceil((v_top - (z.min() - half - pad)) / res)) + 1
    grid = np.zeros((h, w), np.uint8)
    k = max(1, int(round(size / res)))
    c = np.round((a - half - u0) / res).astype(int)
    r = np.round((v_top - z - half) / res).astype(int)
    for dy in range(k):  # each voxel covers k x k cells
        for dx in range(k):
            grid[np.clip(r + dy, 0, h - 1), np.clip(c + dx, 0, w - 1)] = 1
    grid = cv2.morphologyEx(grid, cv2.MORPH_CLOSE, np.ones((kc, kc), np.uint8))
    grid = ndimage.binary_fill_holes(grid)
    lab, n = ndimage.label(grid)
    if n == 0:
        return None
    areas = np.bincount(lab.ravel())[1:] * res ** 2
    keep = np.zeros(n + 1, bool)
    keep[1:] = areas >= cfg.min_area
    cells = keep[lab]
    if not cells.any():
        return None
    return MissedPlane(point, normal, u, u0, v_top, res, cells)


def slab_mesh(plane: MissedPlane) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of the plane's cells: two triangles per cell, corners shared, wound to face ``normal``."""
    h, w = plane.cells.shape
    r, c = np.nonzero(plane.cells)
    corner = np.full((h + 1, w + 1), -1, np.int64)
    cr = np.concatenate([r, r, r + 1, r + 1])
    cc = np.concatenate([c, c + 1, c, c + 1])
    corner[cr, cc] = 0
    used = np.argwhere(corner == 0)
    corner[used[:, 0], used[:, 1]] = np.arange(len(used))
    a = plane.u0 + used[:, 1] * plane.res
    z = plane.v_top - used[:, 0] * plane.res
    verts = plane.point + a[:, None] * plane.u + (z - plane.point[2])[:, None] * _UP
    tl, tr, bl, br = corner[r, c], corner[r, c + 1], corner[r + 1, c], corner[r + 1, c + 1]
    faces = np.concatenate([np.stack([tl, bl, br], 1), np.stack([tl, br, tr], 1)])
    n = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    flip = n @ plane.normal < 0
    faces[flip] = faces[flip][:, ::-1]
    return verts, faces


def view_colours(verts: np.ndarray, normal_per_vertex: np.ndarray, frames: Sequence[Frame], views: Sequence[HoleView],
                 cfg: MissedSurfaceConfig) -> np.ndarray:
    """Per-vertex colour: the median over views that see the vertex unoccluded (no scan surface and no depth
    reading in front of it) and from its front side; grey where none does."""
    from .images import frame_rgb

    samples = np.zeros((len(verts), 3), np.float64)
    per_view: list[tuple[np.ndarray, np.ndarray]] = []
    for f, v in zip(frames, views):
        pc = verts @ v.w2c[:3, :3].T + v.w2c[:3, 3]
        z = pc[:, 2]
        cam = -v.w2c[:3, :3].T @ v.w2c[:3, 3]
        front = np.einsum("ij,ij->i", cam - verts, normal_per_vertex) > 0
        ok = (z > cfg.near_m) & front
        h, w = v.render_z.shape
        px = np.where(ok, v.K[0, 0] * pc[:, 0] / np.maximum(z, 1e-9) + v.K[0, 2], -1)
        py = np.where(ok, v.K[1, 1] * pc[:, 1] / np.maximum(z, 1e-9) + v.K[1, 2], -1)
        ix, iy = np.floor(px + 0.5).astype(int), np.floor(py + 0.5).astype(int)
        ok &= (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
        sel = np.flatnonzero(ok)
        rz = v.render_z[iy[sel], ix[sel]]
        vis = (rz <= 0) | (rz > z[sel] - cfg.margin_m)
        if v.reading_z is not None:
            dz = v.reading_z[iy[sel], ix[sel]]
            vis &= (dz <= 0) | (dz > z[sel] - cfg.margin_m)
        sel = sel[vis]
        if not len(sel):
            continue
        rgb = frame_rgb(f)
        s = rgb.shape[1] / w
        gx = np.clip((px[sel] * s).round().astype(int), 0, rgb.shape[1] - 1)
        gy = np.clip((py[sel] * s).round().astype(int), 0, rgb.shape[0] - 1)
        per_view.append((sel, rgb[gy, gx, :3].astype(np.float64)))
    if not per_view:
        return np.full((len(verts), 3), 128, np.uint8)
    # median per vertex over its views: stack with NaN where a view did not see it
    stack = np.full((len(per_view), len(verts), 3), np.nan)
    for k, (sel, col) in enumerate(per_view):
        stack[k, sel] = col
    seen = ~np.isnan(stack[:, :, 0])
    counts = seen.sum(0)
    samples[counts > 0] = np.nanmedian(stack[:, counts > 0], axis=0)
    samples[counts == 0] = 128
    return np.clip(np.round(samples), 0, 255).astype(np.uint8)


def missed_planes(mesh: TriMesh, frames: Sequence[Frame], raster: Rasterizer, cfg: MissedSurfaceConfig,
                  views: Sequence[HoleView] | None = None) -> list[MissedPlane]:
    """The vertical planes the sensor missed (their regions), from the views' hole pixels."""
    views = list(views) if views is not None else hole_views(frames, raster, cfg)
    if not views:
        return []
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    shape = tuple(int(x) for x in np.maximum(np.ceil((hi - lo) / cfg.voxel_m), 1))
    occ = carve(views, lo, shape, cfg)  # type: ignore[arg-type]
    lab, n = ndimage.label(occ)
    if n:  # volumes too small to hold a front are noise
        sizes = np.bincount(lab.ravel())
        occ = (sizes >= cfg.min_area * cfg.min_depth_m / cfg.voxel_m ** 3)[lab] & occ
    if not occ.any():
        return []
    # the scan's own sparse returns inside the missed volumes (patches of the fronts, handles) fix the planes:
    # the volumes' faces towards the cameras lie in front of the true surface where few views look obliquely
    vol = ndimage.binary_dilation(occ)
    vi = np.floor((mesh.vertices - lo) / cfg.voxel_m).astype(int)
    ok = np.all((vi >= 0) & (vi < np.array(shape)), axis=1)
    ok[ok] = vol[vi[ok, 0], vi[ok, 1], vi[ok, 2]]
    pieces = _pieces(mesh)  # once: both tests read the same connected pieces
    ok &= island_vertices(mesh, cfg.max_island_m2, pieces) & ~flat_vertices(mesh, cfg.flat_island_nz, pieces)
    P = mesh.vertices[ok]
    cams = np.array([-v.w2c[:3, :3].T @ v.w2c[:3, 3] for v in views])
    rng = np.random.default_rng(cfg.seed)
    centres = lo + (np.argwhere(occ) + 0.5) * cfg.voxel_m
    out = []
    axis = room_axis_deg(mesh, pieces, cfg.max_island_m2) if cfg.min_line_m > 0 else None
    for point, normal, inl, line in fit_vertical_planes(P, cams, cfg, rng, cfg.min_returns, cfg.plane_tol_m, axis):
        on = np.abs((centres - point) @ normal) <= cfg.voxel_m  # the volume's section through the plane
        if not on.any():
            continue
        plane = plane_cells(centres[on], point, normal, cfg)
        if plane is None:
            continue
        plane = near_returns(plane, P[inl], cfg, line=line)
        if plane is not None:
            plane.n_returns = len(inl)
            plane.returns = P[inl]
            out.append(plane)
    return out


def near_returns(plane: MissedPlane, returns: np.ndarray, cfg: MissedSurfaceConfig, line: bool = False) -> MissedPlane | None:
    """The plane's region kept within ``cfg.return_reach_m`` of its returns (a wall section behind a cabinet
    holds none), and None when the returns already cover more than ``cfg.max_scanned`` of it (a surface the
    scan holds is not missed) or under ``cfg.min_area`` is left.

    A ``line`` of returns (a base run's top edge) says nothing about how far the surface reaches up or down:
    its region is the pieces of the section its reach touches, within the reach across only."""
    h, w = plane.cells.shape
    c = np.floor(((returns - plane.point) @ plane.u - plane.u0) / plane.res).astype(int)
    r = np.floor((plane.v_top - returns[:, 2]) / plane.res).astype(int)
    ok = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    hits = np.zeros((h, w), np.uint8)
    hits[r[ok], c[ok]] = 1
    k = 2 * int(round(cfg.return_reach_m / plane.res)) + 1
    reach = cv2.dilate(hits, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))).astype(bool)
    if line:
        lab, _ = ndimage.label(plane.cells)
        touched = np.unique(lab[reach & plane.cells])
        columns = reach.any(0)
        reach = np.isin(lab, touched[touched > 0]) & columns[None, :]
    cells = plane.cells & reach
    if cells.sum() * plane.res ** 2 < cfg.min_area:
        return None
    if (hits.astype(bool) & cells).sum() > cfg.max_scanned * cells.sum():  # cells holding a return: what the scan has
        return None
    return MissedPlane(plane.point, plane.normal, plane.u, plane.u0, plane.v_top, plane.res, cells, plane.n_returns,
                       plane.returns)


def merge_layers(planes: Sequence[MissedPlane], cfg: MissedSurfaceConfig) -> list[MissedPlane]:
    """One plane per surface: of planes facing the same way (within ``cfg.merge_deg``) whose regions overlap and
    that lie within ``cfg.merge_m`` of each other (a front's face, the handles in front of it, the worktop edge
    above), the one with most returns is kept and takes the others' regions."""
    order = sorted(range(len(planes)), key=lambda i: -planes[i].n_returns)
    kept: list[MissedPlane] = []
    cos_m = np.cos(np.radians(cfg.merge_deg))
    for i in order:
        p = planes[i]
        layer = next((k for k, q in enumerate(kept) if is_layer_of(p, q, cfg)), None)
        if layer is not None:
            kept[layer] = replace(kept[layer], n_returns=kept[layer].n_returns + p.n_returns)  # the inputs stay as they are
            continue
        corners = _region_points(p)
        host = None
        for k, q in enumerate(kept):
            if q.normal @ p.normal < cos_m:
                continue
            off = (corners - q.point) @ q.normal
            if np.abs(off).max() > cfg.merge_m:
                continue
            if _inside(q, corners).any():
                host = k
                break
        if host is None:
            kept.append(p)
            continue
        q = kept[host]
        grown = plane_cells(np.concatenate([_region_points(q), corners]), q.point, q.normal, cfg, splat=cfg.res_m)
        if grown is not None:
            grown.n_returns = q.n_returns + p.n_returns
            kept[host] = grown
    return kept


def is_layer_of(p: MissedPlane, q: MissedPlane, cfg: MissedSurfaceConfig) -> bool:
    """Are ``p``'s returns a layer of ``q``'s surface: facing within ``cfg.layer_deg`` of it, at least
    ``cfg.layer_share`` of them within ``cfg.merge_m`` of its plane and over its region?

    Why returns, not regions: once a front's face has taken its returns, those left on it are its handles'
    (2-4 cm in front) and a few stray ones; a line fitted through a column of handle returns and a few stray
    points is turned by several degrees, and its region, a slice through the missed volume at that angle,
    runs far from the front's plane, so the regions' distance never finds it a layer (dark tuning 344: a slab
    turned by 7 degrees over a black drawer stack, cut into false drawers, and in front of the stack's own
    slab it hid a third of it from the views)."""
    if p.returns is None or not len(p.returns) or cfg.layer_share <= 0:
        return False
    if float(p.normal @ q.normal) < np.cos(np.radians(cfg.layer_deg)):
        return False
    near = np.abs((p.returns - q.point) @ q.normal) <= cfg.merge_m
    on = near & _inside(q, p.returns)
    return bool(on.mean() >= cfg.layer_share)


def _region_points(p: MissedPlane) -> np.ndarray:
    """World centres of a plane's region cells."""
    r, c = np.nonzero(p.cells)
    a = p.u0 + (c + 0.5) * p.res
    z = p.v_top - (r + 0.5) * p.res
    return p.point + a[:, None] * p.u + (z - p.point[2])[:, None] * _UP


def _inside(p: MissedPlane, pts: np.ndarray) -> np.ndarray:
    """Which points fall on a region cell of ``p`` (projected along its normal)."""
    h, w = p.cells.shape
    c = np.floor(((pts - p.point) @ p.u - p.u0) / p.res).astype(int)
    r = np.floor((p.v_top - pts[:, 2]) / p.res).astype(int)
    ok = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    out = np.zeros(len(pts), bool)
    out[ok] = p.cells[r[ok], c[ok]]
    return out


def seen_planes(planes: Sequence[MissedPlane], views: Sequence[HoleView], cfg: MissedSurfaceConfig) -> list[MissedPlane]:
    """The planes' cells that some view sees first through a hole pixel (no depth reading, the slab in front of
    any scan surface there), grown by ``cfg.close_m``; a slab hidden behind another (a wall behind a missed
    cabinet) or off every hole keeps nothing. Planes left under ``cfg.min_area`` are dropped."""
    if not planes:
        return []
    parts = [slab_mesh(p) for p in planes]
    offs = np.cumsum([0] + [len(v) for v, _ in parts])
    V = np.concatenate([v for v, _ in parts])
    F = np.concatenate([f + o for (_, f), o in zip(parts, offs[:-1])])
    n_faces = [len(f) for _, f in parts]
    face_plane = np.repeat(np.arange(len(planes)), n_faces)
    face_cell = np.concatenate([np.arange(n) % (n // 2) for n in n_faces])  # slab_mesh: two triangles per cell, in cell order
    raster = Rasterizer(TriMesh(V, F))
    seen = [np.zeros(p.cells.shape, np.int32) for p in planes]
    cell_rc = [np.argwhere(p.cells) for p in planes]  # slab_mesh's cell order (row-major nonzero)
    for v in views:
        h, w = v.render_z.shape
        r = raster.render(v.K, np.linalg.inv(v.w2c), w, h)
        hole = (r.face_ids >= 0) & ((v.render_z <= 0) | (r.depth < v.render_z - cfg.margin_m))
        if v.reading_z is not None:
            hole &= v.reading_z <= 0
        f = r.face_ids[hole]
        for k in np.unique(face_plane[f]):
            rc = cell_rc[k][face_cell[f[face_plane[f] == k]]]
            np.add.at(seen[k], (rc[:, 0], rc[:, 1]), 1)
    out = []
    kc = 2 * int(round(cfg.close_m / cfg.res_m)) + 1
    for p, sn in zip(planes, seen):
        cells = cv2.dilate((sn > 0).astype(np.uint8), np.ones((kc, kc), np.uint8)).astype(bool) & p.cells
        if cells.sum() * p.res ** 2 >= cfg.min_area:
            out.append(MissedPlane(p.point, p.normal, p.u, p.u0, p.v_top, p.res, cells, p.n_returns))
    return out


def fill_missed_surface(mesh: TriMesh, frames: Sequence[Frame], raster: Rasterizer,
                        cfg: MissedSurfaceConfig) -> tuple[TriMesh, list[MissedPlane]]:
    """``mesh`` with a coloured slab appended over every missed vertical plane (the mesh itself when none)."""
    views = hole_views(frames, raster, cfg)
    if hole_share(views) < cfg.min_hole_share:
        return mesh, []
    planes = seen_planes(merge_layers(missed_planes(mesh, frames, raster, cfg, views), cfg), views, cfg)
    if not planes:
        return mesh, []
    chosen = np.unique(np.linspace(0, len(frames) - 1, min(cfg.max_views, len(frames))).round().astype(int))
    vs, fs, cs = [mesh.vertices], [mesh.faces], [mesh.colors]
    base = len(mesh.vertices)
    for p in planes:
        v, f = slab_mesh(p)
        cs.append(view_colours(v, np.broadcast_to(p.normal, v.shape), [frames[int(i)] for i in chosen], views, cfg))
        vs.append(v)
        fs.append(f + base)
        base += len(v)
    return TriMesh(np.concatenate(vs), np.concatenate(fs), np.concatenate(cs)), planes


def completed_mesh_path(mesh_path: str | Path, frame_ids: Sequence[str], cfg: MissedSurfaceConfig, cache_dir: str | Path) -> Path:
    """Where the mesh completed with its missed surfaces is kept: keyed by the mesh's bytes, the frames and the config."""
    import hashlib

    h = hashlib.sha256()
    with open(mesh_path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 22), b""):
            h.update(block)
    h.update("\n".join(frame_ids).encode())
    h.update(cfg.model_dump_json().encode())
    h.update(COMPLETION_VERSION.encode())
    key = h.hexdigest()
    return Path(cache_dir) / "missed_surface" / key[:2] / f"{key}.ply"


def complete_scene(scene: SceneInput, raster: Rasterizer, cfg: MissedSurfaceConfig, cache_dir: str | Path) -> SceneInput:
    """``scene`` pointing at its mesh completed with slabs over the surfaces the sensor missed (written once to
    ``cache_dir``, reused after); the scene itself when none is missed. The input mesh is never modified."""
    from ..data.mesh import save_mesh

    path = completed_mesh_path(scene.mesh_path, [f.frame_id for f in scene.frames], cfg, cache_dir)
    empty = path.with_suffix(".none")
    if empty.is_file():
        return scene
    if not path.is_file():
        mesh, planes = fill_missed_surface(raster.mesh, scene.frames, raster, cfg)
        path.parent.mkdir(parents=True, exist_ok=True)
        if not planes:
            empty.write_text("")
            return scene
        save_mesh(path, mesh)
    return scene.model_copy(update={"mesh_path": path,
                                    "notes": scene.notes + (f"mesh completed with slabs over surfaces the depth sensor missed: {path}",)})
