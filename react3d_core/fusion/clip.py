"""Movable-part clipping: keep the slab in front of the part's front plane (handles included).

Why: a whole-object mask (door + carcass frame) back-projects onto the carcass sides and top too.
The front of a door or drawer is the dominant near-vertical plane of the segmented mesh; geometry
more than ``keep_behind_m`` behind it (seen from the segmenting view) is not part of the slab.
A lid (a chest freezer's, a box's) is a horizontal front seen from above: clipped to a vertical plane it
would keep only its lip, so a part whose top outweighs its vertical faces is clipped to its top's plane.
"""

from __future__ import annotations

import numpy as np

from ..config import ClipConfig
from ..data.mesh import TriMesh
from ..geometry import triangle_cross, weighted_median


def face_geometry(mesh: TriMesh, face_ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centroids, unit normals and areas of ``face_ids`` (the mesh's cached ones)."""
    return mesh.face_centroids[face_ids], mesh.face_normals[face_ids], mesh.face_areas[face_ids]


def ransac_plane(points: np.ndarray, weights: np.ndarray, config: ClipConfig, view_dir: np.ndarray | None = None) -> tuple[np.ndarray, float] | None:
    """Near-vertical plane (|n_z| <= max_abs_nz) with the most inlier weight; refined by least squares.

    With ``view_dir`` the inlier weight is scaled by |cos| between the plane normal and the view, so
    the front facing the camera wins over a carcass side panel of similar area.
    """
    if len(points) < 3:
        return None
    rng = np.random.default_rng(config.seed)
    if len(points) > config.ransac_max_points:
        sel = rng.choice(len(points), config.ransac_max_points, replace=False)
        points, weights = points[sel], weights[sel]
    idx = rng.integers(0, len(points), (config.ransac_iterations, 3))
    a = points[idx[:, 0]]
    n = triangle_cross(points, idx)  # the plane through each sampled triple
    ln = np.linalg.norm(n, axis=1)
    ok = ln > 1e-9
    n = n[ok] / ln[ok, None]
    a = a[ok]
    ok = np.abs(n[:, 2]) <= config.max_abs_nz
    n, a = n[ok], a[ok]
    if not len(n):
        return None
    d = -(n * a).sum(1)
    score = ((np.abs(points @ n.T + d) < config.ransac_threshold_m) * weights[:, None]).sum(0)
    if view_dir is not None:
        score = score * np.abs(n @ view_dir)
    best = int(np.argmax(score))
    inl = np.abs(points @ n[best] + d[best]) < config.ransac_threshold_m
    if inl.sum() >= 3:
        c0 = np.average(points[inl], axis=0, weights=weights[inl] + 1e-12)
        _, _, vt = np.linalg.svd((points[inl] - c0) * np.sqrt(weights[inl] + 1e-12)[:, None], full_matrices=False)
        nn = vt[2]
        if abs(nn[2]) <= config.max_abs_nz:
            return nn, float(-nn @ c0)
    return n[best], float(d[best])


def lid_plane(cen: np.ndarray, nrm: np.ndarray, area: np.ndarray, camera: np.ndarray, vertical_area: float,
              config: ClipConfig) -> tuple[np.ndarray, float] | None:
    """The horizontal plane of a lid's top (normal pointing down, into the object), or None for a front.

    A lid is seen from above: its upward faces below the camera cover at least ``lid_min_area_m2`` and
    ``lid_ratio`` times the camera-facing vertical faces (the lip, a front's face). The plane's height is
    the area-weighted median of those faces', so a handle or lip does not pull it."""
    if config.lid_min_area_m2 <= 0:
        return None
    up = (nrm[:, 2] >= np.cos(np.radians(config.lid_max_tilt_deg))) & (cen[:, 2] < camera[2])
    a_up = float(area[up].sum())
    if a_up < config.lid_min_area_m2 or a_up < config.lid_ratio * vertical_area:
        return None
    return np.array([0.0, 0.0, -1.0]), weighted_median(cen[up, 2], area[up])


def is_lid_plane(n: np.ndarray | None, config: ClipConfig) -> bool:
    """Whether ``clip_part`` clipped to a lid's horizontal top (a front's plane is near-vertical)."""
    return n is not None and abs(float(n[2])) > config.max_abs_nz


def clip_part(mesh: TriMesh, face_ids: np.ndarray, camera_center: np.ndarray, config: ClipConfig) -> tuple[np.ndarray, np.ndarray | None, float | None]:
    """Faces of the slab, and the plane (normal pointing away from the camera, offset) or None.

    The plane is fitted to near-vertical faces facing the camera (all near-vertical faces when
    fewer than 3 do, e.g. for unoriented meshes).

    Faces whose centroid lies more than ``keep_behind_m`` behind the plane are dropped; everything in
    front (handles) stays. A lid (:func:`lid_plane`) is clipped to its top's horizontal plane instead.
    """
    face_ids = np.asarray(face_ids, np.int64)
    if not config.enabled or not len(face_ids):
        return face_ids, None, None
    cen, nrm, area = face_geometry(mesh, face_ids)
    vert = np.abs(nrm[:, 2]) <= config.max_abs_nz
    facing = vert & (((np.asarray(camera_center, float) - cen) * nrm).sum(1) > 0)
    if facing.sum() >= 3:  # the front is what the camera sees: not the door's own back face
        vert = facing
    lid = lid_plane(cen, nrm, area, np.asarray(camera_center, float), float(area[vert].sum()), config)
    if lid is not None:
        n, d = lid
        return face_ids[cen @ n + d <= config.keep_behind_m], n, d
    if not vert.any():
        return face_ids, None, None
    foot = np.average(cen[vert], axis=0, weights=area[vert] + 1e-12)
    view = foot - np.asarray(camera_center, float)
    plane = ransac_plane(cen[vert], area[vert], config, view / (np.linalg.norm(view) + 1e-12))
    if plane is None:
        return face_ids, None, None
    n, d = plane
    if n @ (foot - np.asarray(camera_center, float)) < 0:
        n, d = -n, -d
    s = cen @ n + d  # > 0: behind the plane, seen from the camera
    keep = s <= config.keep_behind_m
    return face_ids[keep], n, d
