"""Openable fronts found in the colour frames: planes → fused orthophotos → seam/handle cells → fronts.

The mesh-only rules (fronts.py) need seams in the mesh; real scans have none. Here each large
vertical plane of the mesh is photographed from all the views that see it (orthophoto.py), split at
the seams and between the handles the photos show (front_cells.py), and every door/drawer-sized cell
with a handle — or cut out by seams on at least two sides and not tile-sized — becomes a front whose
faces are the plane's faces inside the cell. Joint type and hinge side come from the same rules as
mesh fronts (handle position and shape, neighbours).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ...data.frames import Frame
from ...data.mesh import TriMesh
from ...raster import Rasterizer
from .facets import face_normals
from .front_cells import Cell, CellParams, find_handles, off_background, split_cells
from .fronts import Front, FrontRules, _joint, _neighbours, doors_in_rows
from .orthophoto import ColourCalibration, Orthophoto, OrthoParams, build_orthophotos
from .planes import Plane, vertical_planes


@dataclass(frozen=True)
class ImageFrontParams:
    ortho: OrthoParams = OrthoParams()
    cells: CellParams = CellParams()
    plane_offset_tol: float = 0.025   # m: faces this close to a plane belong to it
    plane_angle_tol_deg: float = 12.0
    min_plane_area: float = 0.08      # m²
    face_depth: tuple[float, float] = (-0.02, 0.07)  # m behind / in front of the plane taken into a front
    min_tile_side: float = 0.25       # m: handle-less cells smaller than this both ways are tiles, not fronts


def params_from_config(cfg: "HeuristicConfig") -> ImageFrontParams:  # noqa: F821 - pydantic model
    """The image path's parameters from the pipeline config (every threshold lives there)."""
    return ImageFrontParams(
        ortho=OrthoParams(resolution=cfg.ortho_resolution, max_views=cfg.max_views, calibrate=cfg.calibrate_colour),
        cells=CellParams(seam_contrast=cfg.seam_contrast, seam_span=cfg.seam_span, seam_prominence=cfg.seam_prominence,
                         seam_prominence_h=cfg.seam_prominence_h, handle_contrast=cfg.handle_contrast,
                         handle_len=tuple(cfg.handle_len), handle_thick=tuple(cfg.handle_thick)),
        min_tile_side=cfg.min_tile_side)


@dataclass
class ImageFronts:
    """Fronts found in the images, the planes they came from, their orthophotos and the colour
    calibration (kept for reports and debugging)."""

    fronts: list[Front]
    vetoed: list[int]  # indices of mesh fronts the photos show to be clutter (tiles, posters)
    planes: list[Plane]
    orthophotos: list[Orthophoto]
    calibration: ColourCalibration


def coverage_map(o: Orthophoto, mesh: TriMesh, min_area: float = 0.03) -> np.ndarray:
    """Grid pixels covered by the plane's own faces (centroids splatted, small holes closed)."""
    h, w = o.n_views.shape
    cen = mesh.vertices[mesh.faces[o.plane.faces]].mean(1)
    c = np.floor((cen @ o.plane.u - o.u0) / o.res).astype(int)
    r = np.floor((o.v_top - cen[:, 2]) / o.res).astype(int)
    ok = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    cov = np.zeros((h, w), np.uint8)
    cov[r[ok], c[ok]] = 1
    k = max(3, int(round(0.02 / o.res)) | 1)
    cov = cv2.morphologyEx(cov, cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
    cov = cov.astype(np.uint8)
    # stray fragments (bits of floor or wall that happen to lie in the plane) are not part of it
    n, lab, stats, _ = cv2.connectedComponentsWithStats(cov, connectivity=8)
    keep = np.zeros(n, bool)
    keep[1:] = stats[1:, cv2.CC_STAT_AREA] * o.res ** 2 >= min_area
    return keep[lab]


def cov_outline(cov: np.ndarray, px: int = 15) -> np.ndarray:
    """The plane's outline with holes up to ``px`` closed (a handle's scanning shadow is a hole)."""
    return cv2.morphologyEx(cov.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((px, px), np.uint8)).astype(bool)


def protrusion_map(o: Orthophoto, centroids: np.ndarray, normals: np.ndarray,
                   depth: tuple[float, float] = (0.012, 0.09)) -> np.ndarray:
    """Grid pixels under outward-facing faces standing ``depth`` in front of the plane (handles in
    the mesh), splatted by centroid and closed over 2 px."""
    h, w = o.n_views.shape
    p = o.plane
    dn = centroids @ p.n - p.d
    sel = (dn > depth[0]) & (dn < depth[1]) & (normals @ p.n > 0.5)
    c = np.floor((centroids[sel] @ p.u - o.u0) / o.res).astype(int)
    r = np.floor((o.v_top - centroids[sel, 2]) / o.res).astype(int)
    ok = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    out = np.zeros((h, w), np.uint8)
    out[r[ok], c[ok]] = 1
    return cv2.morphologyEx(out, cv2.MORPH_CLOSE, np.ones((5, 5), np.uint8)).astype(bool)


def find_image_fronts(mesh: TriMesh, frames: Sequence[Frame], raster: Rasterizer, read_rgb: Callable[[Frame], np.ndarray],
                      rules: FrontRules = FrontRules(), params: ImageFrontParams = ImageFrontParams(),
                      taken_faces: np.ndarray | None = None, mesh_fronts: Sequence[Front] = ()) -> ImageFronts:
    """Fronts from the colour frames (see module docstring). ``taken_faces`` (bool per face) are
    faces of fronts already found on the mesh: cells overlapping them are left to the mesh rules."""
    cams = np.array([f.c2w[:3, 3] for f in frames]) if len(frames) else np.zeros((1, 3))
    planes = vertical_planes(mesh, cams.mean(0), max_tilt=rules.max_tilt, angle_tol_deg=params.plane_angle_tol_deg,
                             offset_tol=params.plane_offset_tol, min_area=max(params.min_plane_area, rules.min_w * rules.min_h))
    orthos, calib = build_orthophotos(planes, frames, raster, mesh.n_faces, read_rgb, params.ortho)
    centroids = mesh.vertices[mesh.faces].mean(1)
    normals, _ = face_normals(mesh)
    fronts: list[Front] = []
    diffs = []
    for o in orthos:
        cov = coverage_map(o, mesh)
        o.n_views[~cov] = 0  # where the plane's own faces are not (floor, worktop edge seen at the same depth)
        diff = off_background(o, params.cells)
        diffs.append(diff)
        handles = find_handles(o, cov, params.cells, diff, protrusion_map(o, centroids, normals) & cov_outline(cov))
        clutter = (diff > params.cells.handle_contrast) & (o.n_views > 0)
        for h in handles:  # a handle is not clutter
            clutter[h.pixels[:, 1], h.pixels[:, 0]] = False
        p = o.plane
        rel = centroids - p.n * p.d
        in_plane = np.stack([rel @ p.u, centroids[:, 2], rel @ p.n], 1)  # (u, z, depth) of every face, once per plane
        for cell in split_cells(o, cov, handles, params.cells):
            f = _cell_front(o, cell, cov, clutter, in_plane, rules, params, taken_faces)
            if f is not None:
                fronts.append(f)
    # a handle-less cell is a front only beside a front with a handle (tiles and splash-backs have none)
    fronts = [f for f in fronts if f.handle_points is not None
              or any(g.handle_points is not None for g, _ in _neighbours(f, fronts, rules))]
    for f in fronts:
        hpts = f.handle_points if f.handle_points is not None and len(f.handle_points) else None
        f.kind, f.articulation = _joint(f, hpts, _neighbours(f, fronts, rules), rules)
    doors_in_rows(fronts, rules)
    vetoed = [k for k, f in enumerate(mesh_fronts) if _cluttered(f, orthos, diffs, params)]
    return ImageFronts(fronts, vetoed, planes, orthos, calib)


def _cluttered(f: Front, orthos: Sequence[Orthophoto], diffs: Sequence[np.ndarray], params: ImageFrontParams) -> bool:
    """A mesh front whose picture is cluttered (a tiled wall with a socket "handle") is not a front:
    its rectangle in the orthophoto of its plane has more than ``max_clutter`` off-background pixels
    (``diffs``: each orthophoto's off-background map, computed once)."""
    for o, diff_o in zip(orthos, diffs):
        p = o.plane
        if np.dot(p.n, f.n_out) < 0.97 or abs(float(f.center @ p.n) - p.d) > 0.08:
            continue
        h, w = o.n_views.shape
        c0, c1 = int((f.extent_u[0] - o.u0) / o.res), int(np.ceil((f.extent_u[1] - o.u0) / o.res))
        r0, r1 = int((o.v_top - f.extent_v[1]) / o.res), int(np.ceil((o.v_top - f.extent_v[0]) / o.res))
        c0, c1, r0, r1 = max(c0, 0), min(c1, w), max(r0, 0), min(r1, h)
        if c1 - c0 < 5 or r1 - r0 < 5:
            continue
        seen = o.n_views[r0:r1, c0:c1] > 0
        if seen.sum() < 0.3 * seen.size:
            continue
        diff = diff_o[r0:r1, c0:c1]
        return bool((diff[seen] > params.cells.handle_contrast).mean() > params.cells.max_clutter)
    return False


def _cell_front(o: Orthophoto, cell: Cell, cov: np.ndarray, clutter: np.ndarray, in_plane: np.ndarray, rules: FrontRules,
                params: ImageFrontParams, taken: np.ndarray | None) -> Front | None:
    """The front of one cell, or None when the cell is not door/drawer-like."""
    sub = cov[cell.r0:cell.r1, cell.c0:cell.c1]
    if sub.size == 0 or sub.mean() < params.cells.min_seen:
        return None
    seen = o.n_views[cell.r0:cell.r1, cell.c0:cell.c1] > 0
    if seen.any() and clutter[cell.r0:cell.r1, cell.c0:cell.c1][seen].mean() > params.cells.max_clutter:
        return None  # posters, tiles, shelves: a front is a plain panel
    rows, cols = np.nonzero(sub)
    c0, c1 = cell.c0 + cols.min(), cell.c0 + cols.max() + 1   # tighten to the covered area
    r0, r1 = cell.r0 + rows.min(), cell.r0 + rows.max() + 1
    u_a, u_b = o.u0 + c0 * o.res, o.u0 + c1 * o.res
    v_a, v_b = o.v_top - r1 * o.res, o.v_top - r0 * o.res
    w, h = u_b - u_a, v_b - v_a
    if not (rules.min_w <= w <= rules.max_w and rules.min_h <= h <= rules.max_h):
        return None
    if not cell.handles and (cell.cut_sides < 2 or max(w, h) < params.min_tile_side):
        return None  # a plain panel or a tile: not openable by these rules
    p = o.plane
    du, dv, dn = in_plane[:, 0], in_plane[:, 1], in_plane[:, 2]
    inside = ((du > u_a) & (du < u_b) & (dv > v_a) & (dv < v_b)
              & (dn > params.face_depth[0]) & (dn < params.face_depth[1]))
    if taken is not None:
        if taken[inside].sum() > 0.3 * max(inside.sum(), 1):
            return None
        inside &= ~taken
    faces = np.flatnonzero(inside)
    if len(faces) < 4:
        return None
    center = p.to_world(0.5 * (u_a + u_b), 0.5 * (v_a + v_b))
    hp = [p.to_world(*o.to_uv(hd.pixels[:, 0], hd.pixels[:, 1])) for hd in cell.handles]
    f = Front(facet=-1, handle_facets=[], center=center, n_out=p.n.copy(), u=p.u.copy(),
              extent_u=(float(u_a), float(u_b)), extent_v=(float(v_a), float(v_b)), faces=faces)
    f.handle_points = np.concatenate(hp) if hp else None
    return f
