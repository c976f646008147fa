"""Large vertical planes of a scan mesh, found by normal direction and offset rather than by facets.

Real scan meshes (TSDF, laser) have no seams between fronts and round their corners, so facet growing
joins a whole L-shaped cabinet run into one region. Here faces vote for a horizontal normal direction
(area-weighted histogram) and, per dominant direction, for a plane offset; faces near a peak form a
plane, split into spatially connected pieces on a coarse grid in the plane. Fully vectorized.

Where a plane's faces lie (its pieces, its extent, the stretch its direction is refit on) is read from
points spread over the faces no farther apart than half the piece grid, not from their centroids alone: a
decimated scan's faces on flat fronts are 3-5 cm, some much longer, and their centroids are too sparse to
connect a plane's pieces or reach its edges. Faces smaller than that spacing are their centroid, as before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ...config.heuristic import PlanesConfig
from ...data.mesh import TriMesh
from ...geometry import horizontal_right
from .constants import XYZ

_HALF_TURN = 180.0  # deg: a plane's normal direction is taken modulo a half turn (either sign)
_HALF_TURN_BINS = 180  # the direction histogram's 1-degree bins over [0, 180)
_GAUSS_PAD = 4  # sigmas: the refit's density histogram is padded this far for its Gaussian
_MIN_POINTS = 3  # fewer points fix no direction
_PIECE_CLOSE = np.ones((3, 3))  # grid cells touching across one empty cell (or at a corner) are one piece
_SAMPLES_PER_CELL = 2  # faces are sampled at this many points per piece-grid cell along their edges
_LATTICE_MAX = 64  # ... at most this many steps along a face's longest edge
_CORNERS = 3  # a triangle's vertices (and barycentric coordinates)
_CENTROID = np.full((1, _CORNERS), 1.0 / _CORNERS)  # barycentric coordinates of a triangle's centroid


@dataclass
class Plane:
    """One vertical planar region: outward normal ``n`` (horizontal), in-plane right ``u``, offset
    ``d`` (n·x = d), its faces and its extent in (u, z)."""

    n: np.ndarray
    u: np.ndarray
    d: float
    faces: np.ndarray
    extent_u: tuple[float, float]
    extent_v: tuple[float, float]
    area: float

    def to_world(self, uu: np.ndarray, vv: np.ndarray, depth: float = 0.0) -> np.ndarray:
        """Points at in-plane coordinates (uu, vv=z), ``depth`` in front of the plane."""
        uu, vv = np.broadcast_arrays(np.asarray(uu, float), np.asarray(vv, float))
        return (self.n * (self.d + depth) + uu[..., None] * self.u
                + vv[..., None] * np.array([0.0, 0.0, 1.0]))


def _peaks(hist: np.ndarray, min_weight: float, min_sep: int, circular: bool) -> list[int]:
    """Indices of local maxima of a (smoothed) histogram above ``min_weight``, strongest first,
    at least ``min_sep`` bins apart."""
    order = np.argsort(-hist)
    taken: list[int] = []
    n = len(hist)
    half = max(1, min_sep // 2)
    local_max = ndimage.maximum_filter1d(hist, 2 * half + 1, mode="wrap" if circular else "constant") <= hist
    for i in order:
        if hist[i] < min_weight:
            break
        if not local_max[i]:
            continue
        if circular:
            ok = all(min(abs(i - j), n - abs(i - j)) >= min_sep for j in taken)
        else:
            ok = all(abs(i - j) >= min_sep for j in taken)
        if ok:
            taken.append(int(i))
    return taken


def vertical_planes(mesh: TriMesh, cam_center: np.ndarray, cfg: PlanesConfig, *, max_tilt: float,
                    min_area: float | None = None, view_dirs: np.ndarray | None = None) -> list[Plane]:
    """Vertical planes (faces with |n_z| <= ``max_tilt``) of at least ``min_area`` m² (default ``cfg.min_area``).

    A face belongs to a plane when its normal is within ``cfg.angle_tol_deg`` of the plane's horizontal
    normal (either sign) and its centroid within ``cfg.offset_tol`` of the plane. Normals point towards
    the cameras (``view_dirs``: per-face summed directions to cameras that saw it, else
    ``cam_center``). Pieces of one plane separated by more than ``cfg.cell`` become separate planes."""
    min_area = cfg.min_area if min_area is None else min_area
    angle_tol_deg, offset_tol, refit_deg = cfg.angle_tol_deg, cfg.offset_tol, cfg.refit_deg
    if mesh.n_faces == 0:
        return []
    nrm, area, cen = mesh.face_normals, mesh.face_areas, mesh.face_centroids
    vert = (np.abs(nrm[:, 2]) <= max_tilt) & (area > 0)
    if not vert.any():
        return []
    # orientation-free direction histogram over [0, 180) degrees, 1-degree bins
    theta = np.degrees(np.arctan2(nrm[:, 1], nrm[:, 0])) % _HALF_TURN
    bins = np.floor(theta).astype(int) % _HALF_TURN_BINS
    hist = np.bincount(bins[vert], weights=area[vert], minlength=_HALF_TURN_BINS)
    hist = ndimage.uniform_filter1d(hist, cfg.direction_smooth_bins, mode="wrap")
    planes: list[Plane] = []
    peaks = np.array(_peaks(hist, min_area / cfg.direction_peak_div, cfg.direction_min_sep_bins, circular=True), float)
    if not len(peaks):
        return []
    # each face goes to its nearest direction peak (a cabinet turned by 9 degrees is its own plane)
    dist = np.abs(_wrapped(theta[:, None] - peaks[None]))
    nearest = dist.argmin(1)
    vidx = np.flatnonzero(vert)
    sp, sf, sw = surface_samples(mesh.vertices[mesh.faces[vidx]], area[vidx], cfg.cell / _SAMPLES_PER_CELL)
    samples = _Samples(sp, vidx[sf], sw, np.zeros(len(cen), bool))
    for j, peak in enumerate(peaks):
        dth = _wrapped(theta - peak)
        near = vert & (nearest == j) & (np.abs(dth) <= angle_tol_deg)
        if area[near].sum() < min_area:
            continue
        ang = np.radians(peak + np.average(dth[near], weights=area[near]))
        nd = np.array([np.cos(ang), np.sin(ang), 0.0])
        off = cen[near] @ nd
        lo = off.min()
        ob = cfg.offset_bin
        nb = int((off.max() - lo) / ob) + 1
        oh = np.bincount(((off - lo) / ob).astype(int), weights=area[near], minlength=nb)
        oh = ndimage.uniform_filter1d(oh, max(1, int(offset_tol / ob)), mode="constant")
        idx_near = np.flatnonzero(near)
        used = np.zeros(len(cen), bool)  # a refitted plane may reach faces of the next offset peak
        for pk in _peaks(oh, min_area / cfg.offset_peak_div, int(2 * offset_tol / ob), circular=False):
            d0 = lo + (pk + 0.5) * ob
            sel = idx_near[np.abs(off - d0) <= offset_tol]
            if area[sel].sum() < min_area:
                continue
            n_fit = nd
            if refit_deg > 0:  # the face positions fix a wide plane's direction better than its (noisy, skewed) normals
                xy, w = samples.of(sel)
                n_fit, d_fit = fit_direction(xy[:, :2], w, nd, cfg)
                refit = None
                if n_fit is not nd:
                    refit = idx_near[(np.abs(cen[idx_near] @ n_fit - d_fit) <= offset_tol) & ~used[idx_near]]
                # straightened, the plane keeps (nearly) all it had; turned onto another surface, it does not
                if (refit is not None
                        and area[np.intersect1d(refit, sel, assume_unique=True)].sum() >= cfg.refit_keep_share * area[sel].sum()):
                    sel = refit
                else:
                    n_fit = nd
                    sel = sel[~used[sel]]
                if area[sel].sum() < min_area:
                    continue
                used[sel] = True
            planes += _pieces(sel, samples, area, n_fit, float(np.average(cen[sel] @ n_fit, weights=area[sel])), cfg.cell,
                              min_area)
    # orient each plane's normal towards the cameras that see it
    out = []
    for p in planes:
        if view_dirs is not None:
            toward = view_dirs[p.faces].sum(0)
        else:
            toward = cam_center - p.to_world(np.mean(p.extent_u), np.mean(p.extent_v))
        if np.dot(p.n, toward) < 0:
            p = _flip(p)
        out.append(p)
    out.sort(key=lambda p: -p.area)
    return out


def surface_samples(tri: np.ndarray, area: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points on the triangles ``tri`` (F, 3, 3) no farther apart than ``spacing``: a face whose longest edge
    is at most twice ``spacing`` is its centroid; a larger one a barycentric lattice of m = ceil(edge /
    spacing) steps (its vertices included). Returns the points, each one's face (index into ``tri``) and
    weight (the face's ``area`` shared among its points)."""
    edge = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(1) if len(tri) else np.zeros(0)
    m = np.clip(np.ceil(edge / spacing).astype(np.int64), 1, _LATTICE_MAX)
    m[m <= 2] = 1
    pts, face, wt = [], [], []
    for k in np.unique(m):
        idx = np.flatnonzero(m == k)
        if k == 1:
            bary = _CENTROID
        else:
            i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
            ok = i + j <= k
            bary = np.stack([i[ok], j[ok], k - i[ok] - j[ok]], 1) / k
        pts.append(np.einsum("bk,fkx->fbx", bary, tri[idx]).reshape(-1, XYZ))
        face.append(np.repeat(idx, len(bary)))
        wt.append(np.repeat(area[idx] / len(bary), len(bary)))
    if not pts:
        return np.zeros((0, XYZ)), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(pts), np.concatenate(face), np.concatenate(wt)


@dataclass
class _Samples:
    """Points spread over the vertical faces (``surface_samples``): position, face (mesh index), weight."""

    points: np.ndarray
    face: np.ndarray
    weight: np.ndarray
    _mask: np.ndarray  # scratch: one bool per mesh face

    def of(self, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and weights of the faces ``faces`` (mesh indices)."""
        self._mask[faces] = True
        m = self._mask[self.face]
        self._mask[faces] = False
        return self.points[m], self.weight[m]

    def with_face(self, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points of the faces ``faces`` and each one's position in ``faces``."""
        pos = np.full(len(self._mask), -1, np.int64)
        pos[faces] = np.arange(len(faces))
        k = pos[self.face]
        m = k >= 0
        return self.points[m], k[m]


def fit_direction(xy: np.ndarray, w: np.ndarray, nd: np.ndarray, cfg: PlanesConfig) -> tuple[np.ndarray, float]:
    """Horizontal normal and offset of the points ``xy`` (weights ``w``): of the directions within
    ``refit_deg`` of ``nd`` (``refit_step_deg`` apart), the one along which their offsets are sharpest — the
    largest integral of the squared offset density (``refit_bin`` bins smoothed by a ``refit_sigma``
    Gaussian), which every parallel layer
    (wall, door leaf in front of it) raises only when each is sharp; the offset is the density's peak.

    Why: a curved appliance door beside a flat cabinet run skews the normals' mean by a degree, which
    over 2.5 m moves the plane's far end by the offset tolerance; the flat faces' positions do not skew.
    Points without an unbroken stretch of ``refit_min_extent`` along the plane (pieces of several cabinets at
    about the same offset do not count) give ``nd`` back (with the weighted mean offset): over a short
    piece, positions fix the direction no better than normals do, and separate pieces may lie on
    slightly different planes. A turn must make the density at least ``refit_min_gain`` times sharper than
    along the normals' direction: on a real scan's flat walls and cabinets (RedKitchen) the best turn
    gains 1.14-1.35 and changes what is found there; on the tuning scenes' TSDF meshes, beside a curved
    fridge door and on skewed runs, 1.42-2.8 (the default 1.4 lies between the two)."""
    max_angle_deg, bin_m, sigma_m = cfg.refit_deg, cfg.refit_bin, cfg.refit_sigma
    if len(xy) < _MIN_POINTS or _longest_run(xy @ np.array([-nd[1], nd[0]]), cfg.refit_run_step) < cfg.refit_min_extent:
        return nd, float(np.average(xy @ nd[:2], weights=w))
    a0 = np.arctan2(nd[1], nd[0])
    angs = a0 + np.radians(np.arange(-max_angle_deg, max_angle_deg + 1e-9, cfg.refit_step_deg))
    dirs = np.stack([np.cos(angs), np.sin(angs)], 1)                    # (A, 2)
    off = xy @ dirs.T                                                   # (N, A)
    pad = int(np.ceil(_GAUSS_PAD * sigma_m / bin_m))
    lo = off.min(0) - pad * bin_m
    idx = ((off - lo) / bin_m).astype(int)
    nb = int(idx.max()) + pad + 1
    flat = (idx + np.arange(len(angs)) * nb).ravel()
    hist = np.bincount(flat, weights=np.repeat(w, len(angs)), minlength=nb * len(angs)).reshape(len(angs), nb)
    hist = ndimage.gaussian_filter1d(hist, sigma_m / bin_m, axis=1, mode="constant")
    sharp = (hist ** 2).sum(1)
    k = int(np.argmax(sharp))
    if sharp[k] < cfg.refit_min_gain * sharp[len(angs) // 2]:  # not clearly sharper than along the normals: keep them
        return nd, float(np.average(xy @ nd[:2], weights=w))
    b = int(np.argmax(hist[k]))
    n2 = dirs[k]
    return np.array([n2[0], n2[1], 0.0]), float(lo[k] + (b + 0.5) * bin_m)


def _wrapped(deg: np.ndarray) -> np.ndarray:
    """Angle differences (deg) wrapped into [-90, 90): directions modulo a half turn."""
    return (deg + _HALF_TURN / 2) % _HALF_TURN - _HALF_TURN / 2


def _longest_run(t: np.ndarray, step: float) -> float:
    """Length of the longest unbroken stretch of the coordinates ``t`` on a ``step`` grid."""
    occ = np.zeros(int((t.max() - t.min()) / step) + 1, bool)
    occ[((t - t.min()) / step).astype(int)] = True
    padded = np.concatenate([[False], occ, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return float((edges[1::2] - edges[::2]).max() * step)


def _flip(p: Plane) -> Plane:
    u = horizontal_right(-p.n)
    return Plane(-p.n, u, -p.d, p.faces, (-p.extent_u[1], -p.extent_u[0]), p.extent_v, p.area)


def _pieces(sel: np.ndarray, samples: _Samples, area: np.ndarray, n: np.ndarray, d: float, cell: float,
            min_area: float) -> list[Plane]:
    """Split the faces ``sel`` of one plane into pieces connected on a ``cell`` grid (their surface
    samples'); a piece's extent is its samples'."""
    u = horizontal_right(n)  # right-hand side when looking at the plane from its front
    pts, owner = samples.with_face(sel)
    pu, pv = pts @ u, pts[:, 2]
    iu = np.floor((pu - pu.min()) / cell).astype(int)
    iv = np.floor((pv - pv.min()) / cell).astype(int)
    grid = np.zeros((iv.max() + 1, iu.max() + 1), bool)
    grid[iv, iu] = True
    lab, k = ndimage.label(ndimage.binary_closing(grid, _PIECE_CLOSE, border_value=0) | grid, _PIECE_CLOSE)
    sl = lab[iv, iu]
    fl = np.zeros(len(sel), np.int64)
    fl[owner] = sl  # a face's samples lie closer together than a cell: one piece
    out = []
    for j in range(1, k + 1):
        m = fl == j
        a = float(area[sel[m]].sum())
        if a < min_area:
            continue
        ms = sl == j
        out.append(Plane(n.copy(), u, d, sel[m], (float(pu[ms].min()), float(pu[ms].max())),
                         (float(pv[ms].min()), float(pv[ms].max())), a))
    return out
