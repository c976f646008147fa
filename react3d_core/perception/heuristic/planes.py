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
from scipy import ndimage, sparse

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
_KEY_STRIDE = 1 << 32  # a grid cell's key: its u index times this plus its v index (v indices stay far below)
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
    averaged: bool = False  # found only by normals averaged over neighbouring faces (the last vote)
    residual: bool = False  # found by the faces no offset peak took (a front set back beside a larger one)

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
    the outside (``outward_signs``: the faces' own normals, else ``view_dirs``, per-face summed directions
    to cameras that saw it, else ``cam_center``). Pieces of one plane separated by more than ``cfg.cell`` become separate planes."""
    min_area = cfg.min_area if min_area is None else min_area
    if mesh.n_faces == 0:
        return []
    nrm, area, cen = mesh.face_normals, mesh.face_areas, mesh.face_centroids
    vert = (np.abs(nrm[:, 2]) <= max_tilt) & (area > 0)
    if not vert.any():
        return []
    # orientation-free direction of every face's normal over [0, 180) degrees
    theta = _direction_deg(nrm)
    ns = smoothed_normals(mesh, cfg.smooth_rings) if cfg.smooth_rings > 0 else nrm
    vert_s = (np.abs(ns[:, 2]) <= max_tilt) & (area > 0)
    vidx = np.flatnonzero(vert | vert_s)
    sp, sf, sw = surface_samples(mesh.vertices[mesh.faces[vidx]], area[vidx], cfg.cell / _SAMPLES_PER_CELL)
    samples = _Samples(sp, vidx[sf], sw, np.zeros(len(cen), bool))
    planes, found = _vote(vert, theta, area, cen, samples, cfg, min_area, [])
    for _ in range(cfg.revote_rounds):
        # faces no plane explains vote again, away from the directions found: a piece of furniture turned
        # by ~10 degrees in the room is hidden in the first vote by the tail of the walls' peak
        more, dirs = _vote(vert & ~_explained(planes, cen, cfg), theta, area, cen, samples, cfg, min_area, found)
        if not more:
            break
        planes += more
        found += dirs
    if cfg.smooth_rings > 0:
        # A small piece on a 1 cm TSDF scan has face normals spread by +-15 degrees and no direction peaks;
        # averaged over a few rings of neighbours they agree. Only faces no plane explains vote so, so the
        # raw-normal planes stay as they are (averaged everywhere, normals bend round edges and handles and
        # moved them). At any direction: a chest turned 5 degrees from its wall peaks within the separation
        # kept from the wall's peak, whose faces are explained by now. A lower peak suffices (averaged normals
        # still spread by +-5 degrees); the plane must still hold min_area.
        more, _ = _vote(vert_s & ~_explained(planes, cen, cfg), _direction_deg(ns), area, cen, samples,
                        cfg.model_copy(update={"direction_peak_div": cfg.smooth_peak_div}), min_area, [])
        for p in more:
            p.averaged = True
        planes += more
    if any(p.residual for p in planes):
        planes = _unstacked(planes, samples, cfg)
    signs = outward_signs(planes, nrm, area, cam_center, view_dirs, cfg.normal_agree)
    out = [p if sg > 0 else _flip(p) for p, sg in zip(planes, signs)]
    out.sort(key=lambda p: -p.area)
    return out


def outward_signs(planes: list[Plane], nrm: np.ndarray, area: np.ndarray, cam_center: np.ndarray,
                  view_dirs: np.ndarray | None, normal_agree: float) -> list[float]:
    """Per plane +1 when its normal points out of the surface, towards the cameras that saw it, else -1.

    By the plane's faces' own normals when their area-weighted mean along ``p.n`` is at least
    ``normal_agree`` either way (0: never): a scan mesh's faces face the free space the sensor looked
    through. Else (and for every plane when the mesh's winding is not to be trusted: the planes whose
    normals lean disagree with the cameras on more area than they agree, as on a mesh wound inside out)
    by the cameras: ``view_dirs`` (per face, summed directions to the cameras that saw it) when given and
    not all zero, else towards ``cam_center``.

    Why normals first: the cameras' mean position lies behind a piece standing free in the room that faces
    a wall, and the cameras that saw a plane's faces can lie on both sides of it (a wall cabinet hung in a
    galley, seen from behind over its top: its front plane was turned to the wall); the faces' normals
    agree on the side the scan saw across the whole plane. Both sides of a thin board in one plane
    cancel out; then the cameras decide. The walls, the largest planes, are seen from inside the room,
    so on a mesh wound the right way most of the area agrees."""
    cams, leans, areas = [], [], []
    for p in planes:
        a = area[p.faces]
        leans.append(float((nrm[p.faces] @ p.n) @ a) / float(a.sum()) if a.sum() > 0 else 0.0)
        areas.append(p.area)
        toward = view_dirs[p.faces].sum(0) if view_dirs is not None else np.zeros(len(p.n))
        if not np.any(toward):
            toward = cam_center - p.to_world(np.mean(p.extent_u), np.mean(p.extent_v))
        cams.append(1.0 if np.dot(p.n, toward) >= 0 else -1.0)
    lean, cam, w = np.array(leans), np.array(cams), np.array(areas)
    clear = (np.abs(lean) >= normal_agree) if normal_agree > 0 else np.zeros(len(planes), bool)
    agree = clear & (np.sign(lean) == cam)
    if w[agree].sum() < w[clear & ~agree].sum():
        clear[:] = False
    return np.where(clear, np.sign(lean), cam).tolist()


def _explained(planes: list[Plane], cen: np.ndarray, cfg: PlanesConfig) -> np.ndarray:
    """Faces a plane holds or that lie on one (within ``offset_tol`` of it, inside its extent grown by
    ``cell``). Why the second: a TSDF wall's faces with normals beyond the angle tolerance (+-9 degrees of
    noise, with tails) are still the wall; left to vote again, their many square metres pull the
    direction of a turned piece's plane by several degrees towards the wall's."""
    out = np.zeros(len(cen), bool)
    for p in planes:
        out[p.faces] = True
        near = np.flatnonzero(np.abs(cen @ p.n - p.d) <= cfg.offset_tol)
        uu, vv = cen[near] @ p.u, cen[near, 2]
        inside = ((uu >= p.extent_u[0] - cfg.cell) & (uu <= p.extent_u[1] + cfg.cell)
                  & (vv >= p.extent_v[0] - cfg.cell) & (vv <= p.extent_v[1] + cfg.cell))
        out[near[inside]] = True
    return out


def _direction_deg(nrm: np.ndarray) -> np.ndarray:
    """Orientation-free directions (deg, [0, 180)) of the normals ``nrm`` (N, 3) projected on the floor."""
    return np.degrees(np.arctan2(nrm[:, 1], nrm[:, 0])) % _HALF_TURN


def smoothed_normals(mesh: TriMesh, rings: int) -> np.ndarray:
    """Face normals averaged (area-weighted) over the faces within ``rings`` steps through shared vertices,
    unit length. Sparse face-vertex incidence products: linear in the mesh size."""
    f = mesh.faces
    nf = len(f)
    inc = sparse.csr_matrix((np.ones(f.size), (f.ravel(), np.repeat(np.arange(nf), f.shape[1]))),
                            shape=(len(mesh.vertices), nf))
    n = mesh.face_normals * mesh.face_areas[:, None]
    for _ in range(rings):
        n = inc.T @ (inc @ n)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def _direction(n: np.ndarray) -> float:
    """A horizontal normal's orientation-free direction in [0, 180) degrees."""
    return float(np.degrees(np.arctan2(n[1], n[0])) % _HALF_TURN)


def _vote(cand: np.ndarray, theta: np.ndarray, area: np.ndarray, cen: np.ndarray, samples: _Samples, cfg: PlanesConfig,
          min_area: float, found: list[float]) -> tuple[list[Plane], list[float]]:
    """Planes of the faces ``cand`` (bool per face; ``theta``: their normals' directions in degrees;
    ``samples``: points spread over the vertical faces, for the refit and the pieces) by a
    direction vote, then an offset vote per direction, and the direction peaks (degrees) that gave a plane.
    Direction peaks closer than ``direction_min_sep_bins`` to one of ``found`` are not taken. A piece that is
    a slice through a surface standing at another angle (``is_slice``: a turned cabinet's front cut along
    a wall's direction) is left out, and its faces stay free for the next vote."""
    angle_tol_deg, offset_tol = cfg.angle_tol_deg, cfg.offset_tol
    if not cand.any():
        return [], []
    bins = np.floor(theta).astype(int) % _HALF_TURN_BINS
    hist = np.bincount(bins[cand], weights=area[cand], minlength=_HALF_TURN_BINS)
    hist = ndimage.uniform_filter1d(hist, cfg.direction_smooth_bins, mode="wrap")
    peaks = np.array([k for k in _peaks(hist, min_area / cfg.direction_peak_div, cfg.direction_min_sep_bins, circular=True)
                      if all(abs(_wrapped(np.array(k - f))) >= cfg.direction_min_sep_bins for f in found)], float)
    planes: list[Plane] = []
    if not len(peaks):
        return [], []
    # each face goes to its nearest direction peak (a cabinet turned by 9 degrees is its own plane)
    dist = np.abs(_wrapped(theta[:, None] - peaks[None]))
    nearest = dist.argmin(1)
    voted: set[float] = set()
    for j, peak in enumerate(peaks):
        dth = _wrapped(theta - peak)
        near = cand & (nearest == j) & (np.abs(dth) <= angle_tol_deg)
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
        first = _peaks(oh, min_area / cfg.offset_peak_div, int(2 * offset_tol / ob), circular=False)
        firsts: list[Plane] = []
        for pk in first:
            firsts += _take(lo + (pk + 0.5) * ob, idx_near, off, nd, used, cen, area, samples, cfg, min_area, theta)
        planes += firsts
        if firsts:
            voted.add(float(peak))
        if cfg.residual_dip > 0 and first:
            # a small front a few cm behind a large one (a microwave on its cabinet) peaks within the large
            # one's separation, on its flank: the faces no peak took vote again, and a peak of theirs from
            # which all faces' offsets dip on the way to the nearest peak taken is a plane (a wall's tail,
            # or a bent wall's plateau, has no such dip)
            d_first = lo + (np.array(first) + 0.5) * ob
            rest = ~used[idx_near] & (np.abs(off[:, None] - d_first[None]).min(1) > offset_tol)
            if rest.any():
                rh = np.bincount(((off[rest] - lo) / ob).astype(int), weights=area[idx_near[rest]], minlength=nb)
                rh = ndimage.uniform_filter1d(rh, max(1, int(offset_tol / ob)), mode="constant")
                for pk in _peaks(rh, min_area / cfg.offset_peak_div, int(2 * offset_tol / ob), circular=False):
                    f = min(first, key=lambda q: abs(q - pk))
                    between = oh[min(pk, f) + 1:max(pk, f)]
                    if not len(between) or between.min() > cfg.residual_dip * oh[pk]:
                        continue
                    for p in _take(lo + (pk + 0.5) * ob, idx_near[rest], off[rest], nd, used, cen, area, samples, cfg,
                                   min_area, theta):
                        p.residual = True
                        planes.append(p)
    # the directions voted for, not the planes' own: a small plane refit a few degrees off its peak (a
    # wall's strip behind a turned chest, 4 degrees off) would bar the direction the next vote needs
    return planes, sorted(voted)


def _take(d0: float, idx: np.ndarray, off: np.ndarray, nd: np.ndarray, used: np.ndarray, cen: np.ndarray,
          area: np.ndarray, samples: _Samples, cfg: PlanesConfig, min_area: float, theta: np.ndarray,
          ) -> list[Plane]:
    """The plane at offset ``d0`` along ``nd`` of the faces ``idx`` (offsets ``off``), refit when its faces'
    positions fix its direction better: its pieces of at least ``min_area`` that are no slice."""
    offset_tol = cfg.offset_tol
    sel = idx[np.abs(off - d0) <= offset_tol]
    if area[sel].sum() < min_area:
        return []
    n_fit = nd
    if cfg.refit_deg > 0:  # the face positions fix a wide plane's direction better than its (noisy, skewed) normals
        xy, w = samples.of(sel)
        n_fit, d_fit = fit_direction(xy[:, :2], w, nd, cfg)
        refit = None
        if n_fit is not nd:
            refit = idx[(np.abs(cen[idx] @ n_fit - d_fit) <= offset_tol) & ~used[idx]]
        # straightened, the plane keeps (nearly) all it had; turned onto another surface, it does not
        if (refit is not None
                and area[np.intersect1d(refit, sel, assume_unique=True)].sum() >= cfg.refit_keep_share * area[sel].sum()):
            sel = refit
        else:
            n_fit = nd
            sel = sel[~used[sel]]
        if area[sel].sum() < min_area:
            return []
        used[sel] = True
    return [p for p in _pieces(sel, samples, area, n_fit, float(np.average(cen[sel] @ n_fit, weights=area[sel])),
                               cfg.cell, min_area)
            if not (cfg.max_skew_deg > 0 and is_slice(p, theta, area, cen, cfg.max_skew_deg))]


def _unstacked(planes: list[Plane], samples: _Samples, cfg: PlanesConfig) -> list[Plane]:
    """``planes`` less the residual ones stacked on another's footprint: a front's frame or panel, the plinth
    behind its fronts, a TSDF scan's doubled surface are relief on one front; a microwave set back on its
    cabinet stands beside the cabinet's front, not on it."""
    cos_tol = np.cos(np.radians(cfg.angle_tol_deg))
    main = [q for q in planes if not q.residual]
    out = []
    for p in planes:
        if p.residual:
            mid = p.to_world(np.mean(p.extent_u), np.mean(p.extent_v))
            aligned = [q for q in main if abs(q.n @ p.n) >= cos_tol]
            # within the offset tolerance of a plane it overlaps, it is that plane's surface (cut off it by the
            # direction the larger one was refit on)
            if any(abs(mid @ q.n - q.d) <= cfg.offset_tol and _overlap(p, q, cfg.cell) for q in aligned):
                continue
            close = [q.faces for q in aligned if abs(mid @ q.n - q.d) <= cfg.residual_stack_depth]
            if close and layer_share(p, np.concatenate(close), samples, cfg.cell) > cfg.residual_max_stack:
                continue
        out.append(p)
    return out


def _overlap(p: Plane, q: Plane, grow: float) -> bool:
    """Do the extents of the planes ``p`` and ``q`` (alike in direction) overlap, ``q``'s grown by ``grow``?"""
    ends = p.to_world(np.array(p.extent_u), np.full(2, np.mean(p.extent_v))) @ q.u
    return bool(ends.max() >= q.extent_u[0] - grow and ends.min() <= q.extent_u[1] + grow
                and p.extent_v[1] >= q.extent_v[0] - grow and p.extent_v[0] <= q.extent_v[1] + grow)


def layer_share(p: Plane, others: np.ndarray, samples: _Samples, cell: float) -> float:
    """Share of the plane piece's grid cells (``cell`` m, in its own u, v) that the faces ``others`` also
    occupy: a piece stacked on another's footprint (a front's frame, a door's panel, a plinth behind its
    fronts) rather than beside it."""
    own, _ = samples.with_face(p.faces)
    oth, _ = samples.with_face(others)
    if not len(own) or not len(oth):
        return 0.0
    def keys(pts: np.ndarray) -> np.ndarray:
        iu = np.floor(pts @ p.u / cell).astype(np.int64)
        iv = np.floor(pts[:, 2] / cell).astype(np.int64)
        return iu * _KEY_STRIDE + iv
    mine = np.unique(keys(own))
    return float(np.isin(mine, keys(oth)).mean())


def is_slice(p: Plane, theta: np.ndarray, area: np.ndarray, cen: np.ndarray, max_turn_deg: float) -> bool:
    """Is the piece a slice cut through a surface turned from it, not a plane? Its faces' positions lie
    on a line turned by more than ``max_turn_deg`` from the piece's direction (least squares of their
    offsets against their place along it), and their normals (``theta``, degrees) lean the same way.

    Why positions: the plane's faces are those whose normals lie within the angle tolerance, so on a
    TSDF scan (normals spread by +-9 degrees) a front turned by 11 degrees shows only a 4-degree mean
    lean, while the positions of a 25 cm slice through it turn by the full 11 degrees (a flat plane's
    by under 2). Why both: two parallel layers a few cm apart within one short piece (a door beside
    its carcass edge) tilt the fitted line too, but leave the normals straight."""
    w, c = area[p.faces], cen[p.faces]
    uu, off = c @ p.u, c @ p.n
    du, do = uu - np.average(uu, weights=w), off - np.average(off, weights=w)
    var = float(np.average(du ** 2, weights=w))
    if var <= 0:
        return False
    # u = z x n, so a surface turned counter-clockwise (normal towards +u) has offsets falling along u
    turn = -np.degrees(np.arctan(float(np.average(du * do, weights=w)) / var))
    lean = float(np.average(_wrapped(theta[p.faces] - _direction(p.n)), weights=w))
    return bool(abs(turn) > max_turn_deg and np.sign(lean) == np.sign(turn))


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
    return Plane(-p.n, u, -p.d, p.faces, (-p.extent_u[1], -p.extent_u[0]), p.extent_v, p.area, p.averaged, p.residual)


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


def share_behind(mesh: TriMesh, n: np.ndarray, d: float, depth: float, wall_back: float, min_cos: float) -> float:
    """Share of the scan's surface area lying more than ``depth`` behind the plane n·x = d (``n`` pointing
    into the room), less the wall's own outer side: surface up to ``wall_back`` behind it facing away
    (cosine to ``n`` below -``min_cos``), which no camera in the room saw. Why: a scan is taken from inside
    a room, so an outer wall has nothing behind it, while a piece standing in the room has its carcass and
    the room's other walls and floor behind its front."""
    cen, area, nrm = mesh.face_centroids, mesh.face_areas, mesh.face_normals
    off = cen @ n - d
    own_back = (off > -wall_back) & (nrm @ n < -min_cos)
    return float(area[(off < -depth) & ~own_back].sum()) / max(float(area.sum()), 1e-12)
