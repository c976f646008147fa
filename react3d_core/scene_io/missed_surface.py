"""Surfaces the depth sensor missed: slabs over vertical planes the scan mesh lacks but the views show.

ToF and structured-light sensors return no depth on black and glossy fronts, so a fused scan has holes
where such fronts are (often nothing behind them either: the front hid it). Every later stage works on
mesh faces, so a front the mesh lacks could never become a part. Here the holes are found from the
views: a pixel whose ray hits no scan surface and whose depth frame has no reading looks at something
the sensor missed. Space is carved on a voxel grid (a voxel is *free* when some view sees a scan surface
or a depth reading behind it, *missed* when views look at it through such hole pixels); the missed
voxels that no view saw through form the volumes the sensor missed. Their vertical faces towards the
cameras are the missing surfaces: each is fitted with a vertical plane (moved onto the scan's own sparse
returns on it, when there are any), rasterised on the plane, and added to the mesh as a flat slab
coloured from the views. The original vertices and faces keep their ids (ground truth indexes them);
the slab's are appended. Perception then finds fronts on the slab as on any other plane.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage

from ..config.scene_io import MissedSurfaceConfig
from ..data.frames import Frame, SceneInput
from ..data.mesh import TriMesh
from ..raster import Rasterizer

_UP = np.array([0.0, 0.0, 1.0])
COMPLETION_VERSION = "1"  # what a completed mesh in the cache was made by


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


def carve(views: Sequence[HoleView], lo: np.ndarray, shape: tuple[int, int, int], cfg: MissedSurfaceConfig) -> np.ndarray:
    """Voxels (grid from ``lo``, side ``cfg.voxel_m``) the sensor missed: seen through hole pixels in at least
    ``cfg.min_views`` views and in front of a scan surface or a depth reading in at most ``cfg.max_free``."""
    idx = np.indices(shape, dtype=np.int32).reshape(3, -1).T
    centres = (lo + (idx + 0.5) * cfg.voxel_m).astype(np.float32)
    missed = np.zeros(len(centres), np.int16)
    free = np.zeros(len(centres), np.int16)
    margin = cfg.margin_m
    for v in views:
        h, w = v.render_z.shape
        pc = centres @ v.w2c[:3, :3].T.astype(np.float32) + v.w2c[:3, 3].astype(np.float32)
        z = pc[:, 2]
        ok = z > cfg.near_m
        px = np.full(len(z), -1, np.int64)
        py = np.full(len(z), -1, np.int64)
        px[ok] = np.floor(v.K[0, 0] * pc[ok, 0] / z[ok] + v.K[0, 2] + 0.5).astype(np.int64)
        py[ok] = np.floor(v.K[1, 1] * pc[ok, 1] / z[ok] + v.K[1, 2] + 0.5).astype(np.int64)
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
        free[sel[is_free]] += 1
        missed[sel[hole]] += 1
    return ((missed >= cfg.min_views) & (free <= cfg.max_free)).reshape(shape)


def fit_vertical_planes(pts: np.ndarray, normals: np.ndarray, cameras: np.ndarray, cfg: MissedSurfaceConfig,
                        rng: np.random.Generator, need: int, tol: float) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Vertical planes through the boundary points facing a camera side (RANSAC: a point and its normal made
    horizontal fix a plane): ``(point, normal, inlier indices)`` while a plane gathers ``cfg.min_area`` m² of voxels."""
    vert = np.abs(normals[:, 2]) < np.sin(np.radians(cfg.max_tilt_deg))
    todo = np.flatnonzero(vert)
    out = []
    cos_n = np.cos(np.radians(cfg.normal_tol_deg))
    while len(todo) >= need:
        P, N = pts[todo], normals[todo]
        a = rng.integers(0, len(todo), cfg.ransac_iters)
        n = N[a] * np.array([1.0, 1.0, 0.0])  # each hypothesis: a point and its own normal, made horizontal
        nn = np.linalg.norm(n, axis=1)
        good = nn > 0.5
        if not good.any():
            break
        n = n[good] / nn[good, None]
        p0 = P[a[good]]
        scores = np.zeros(len(n), np.int64)
        for k in range(0, len(n), 32):  # plane batches: (32, points) at a time
            sd = np.einsum("kij,kj->ki", P[None] - p0[k:k + 32, None], n[k:k + 32])
            agree = N @ n[k:k + 32].T
            scores[k:k + 32] = ((np.abs(sd) <= tol) & (agree.T >= cos_n)).sum(1)
        best = int(np.argmax(scores))
        if scores[best] < need:
            break
        nb, pb = n[best], p0[best]
        inl = (np.abs((P - pb) @ nb) <= tol) & (N @ nb >= cos_n)
        # refit the offset to the inliers' median (the normal stays horizontal)
        pb = pb + nb * float(np.median((P[inl] - pb) @ nb))
        if (np.einsum("ij,j->i", cameras - pb, nb) > 0).mean() < cfg.min_camera_share:
            todo = todo[~inl]  # a face no camera stands in front of (the back of a volume): not a surface seen
            continue
        out.append((pb, nb, todo[inl]))
        todo = todo[~inl]
    return out


def plane_cells(pts: np.ndarray, point: np.ndarray, normal: np.ndarray, cfg: MissedSurfaceConfig) -> MissedPlane | None:
    """The plane's missed region rasterised at ``cfg.res_m``: voxel footprints splatted, gaps up to
    ``cfg.close_m`` closed, holes filled, pieces under ``cfg.min_area`` dropped (None: nothing left)."""
    u = np.cross(_UP, normal)
    u /= np.linalg.norm(u)
    a, z = (pts - point) @ u, pts[:, 2]
    res = cfg.res_m
    half = cfg.voxel_m / 2
    kc = max(1, int(round(cfg.close_m / res))) | 1
    pad = kc * res  # room for the closing at the region's edges
    u0, v_top = float(a.min() - half - pad), float(z.max() + half + pad)
    w = int(np.ceil((a.max() + half + pad - u0) / res)) + 1
    h = int(np.ceil((v_top - (z.min() - half - pad)) / res)) + 1
    grid = np.zeros((h, w), np.uint8)
    k = max(1, int(round(cfg.voxel_m / res)))
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
    P, N = mesh.vertices[ok], mesh.vertex_normals[ok]
    cams = np.array([-v.w2c[:3, :3].T @ v.w2c[:3, 3] for v in views])
    rng = np.random.default_rng(cfg.seed)
    centres = lo + (np.argwhere(occ) + 0.5) * cfg.voxel_m
    out = []
    for point, normal, inl in fit_vertical_planes(P, N, cams, cfg, rng, cfg.min_returns, cfg.plane_tol_m):
        on = np.abs((centres - point) @ normal) <= cfg.voxel_m  # the volume's section through the plane
        if not on.any():
            continue
        plane = plane_cells(centres[on], point, normal, cfg)
        if plane is None:
            continue
        plane = near_returns(plane, P[inl], cfg)
        if plane is not None:
            out.append(plane)
    return out


def near_returns(plane: MissedPlane, returns: np.ndarray, cfg: MissedSurfaceConfig) -> MissedPlane | None:
    """The plane's region kept within ``cfg.return_reach_m`` of its returns (a wall section behind a cabinet
    holds none), and None when the returns already cover more than ``cfg.max_scanned`` of it (a surface the
    scan holds is not missed) or under ``cfg.min_area`` is left."""
    h, w = plane.cells.shape
    c = np.floor(((returns - plane.point) @ plane.u - plane.u0) / plane.res).astype(int)
    r = np.floor((plane.v_top - returns[:, 2]) / plane.res).astype(int)
    ok = (c >= 0) & (c < w) & (r >= 0) & (r < h)
    hits = np.zeros((h, w), np.uint8)
    hits[r[ok], c[ok]] = 1
    k = 2 * int(round(cfg.return_reach_m / plane.res)) + 1
    reach = cv2.dilate(hits, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))).astype(bool)
    cells = plane.cells & reach
    if cells.sum() * plane.res ** 2 < cfg.min_area:
        return None
    if (hits.astype(bool) & cells).sum() > cfg.max_scanned * cells.sum():  # cells holding a return: what the scan has
        return None
    return MissedPlane(plane.point, plane.normal, plane.u, plane.u0, plane.v_top, plane.res, cells)


def fill_missed_surface(mesh: TriMesh, frames: Sequence[Frame], raster: Rasterizer,
                        cfg: MissedSurfaceConfig) -> tuple[TriMesh, list[MissedPlane]]:
    """``mesh`` with a coloured slab appended over every missed vertical plane (the mesh itself when none)."""
    views = hole_views(frames, raster, cfg)
    planes = missed_planes(mesh, frames, raster, cfg, views)
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
