"""Triangle-id and depth buffers by ray casting (Open3D/Embree) through pixel centres.

Ray casting is exact for any principal point and image size: a pixel (u, v) looks along
K^-1 [u, v, 1], so there is no projection-matrix sign convention to get wrong (the reference's
OpenGL path had a principal-point sign error). ``depth`` is the z-depth along the optical axis.

:class:`Rasterizer` is the project's one entry point to ray casting: besides frame buffers it casts
arbitrary rays (:meth:`Rasterizer.cast_rays`: distance, face, barycentric uv, face normal) and
answers closest-point and distance queries on the same BVH.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..data.frames import Frame, Intrinsics
from ..data.mesh import TriMesh

INVALID = -1


@dataclass
class RayHits:
    """First hits of a batch of rays, shaped like the rays' leading axes. ``t`` float32 is in units of
    the direction's length (inf: no hit); ``face_ids`` int64 (-1: no hit); ``uvs`` float32 (..., 2)
    barycentric coordinates of the hit in its face; ``normals`` float32 (..., 3) the hit face's normal."""

    t: np.ndarray
    face_ids: np.ndarray
    uvs: np.ndarray
    normals: np.ndarray


def pixel_rays(K: np.ndarray, c2w: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Camera centre (float32, (3,)) and per-pixel world directions (H, W, 3) through pixel centres
    (integer coordinates), K^-1 [u, v, 1] rotated to the world: not normalised, so a hit's ``t`` is its
    z-depth."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
    dc = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1)
    return c2w[:3, 3].astype(np.float32), dc @ c2w[:3, :3].astype(np.float32).T


@dataclass
class RasterResult:
    """One frame's buffers: ``face_ids`` int32 (H, W) with -1 for background; ``depth`` float32 metres (0 = none)."""

    frame_id: str
    face_ids: np.ndarray
    depth: np.ndarray


class Rasterizer:
    """Holds the mesh in an Embree BVH once; renders any number of views.

    The BVH (and Open3D) is built on the first ray cast, not here: a conversion whose every step is
    cached never casts one, and building it was most of such a run's start-up. Thread-safe."""

    def __init__(self, mesh: TriMesh, n_threads: int = 0) -> None:
        self.mesh = mesh
        self._n_threads = n_threads
        self._built: Any = None
        self._lock = threading.Lock()

    @property
    def _scene(self) -> Any:
        if self._built is None:
            with self._lock:
                if self._built is None:
                    import open3d as o3d

                    scene = o3d.t.geometry.RaycastingScene(nthreads=self._n_threads)
                    vt = o3d.core.Tensor(np.ascontiguousarray(self.mesh.vertices, dtype=np.float32))
                    ft = o3d.core.Tensor(np.ascontiguousarray(self.mesh.faces, dtype=np.uint32))
                    scene.add_triangles(vt, ft)
                    self._built = scene
        return self._built

    def cast_rays(self, origins: np.ndarray, directions: np.ndarray) -> RayHits:
        """First hit along each ray (origins and directions (..., 3), cast to float32; directions need
        not be unit: ``t`` is in units of their length)."""
        import open3d as o3d

        o = np.asarray(origins, np.float32)
        d = np.asarray(directions, np.float32)
        shape = np.broadcast_shapes(o.shape, d.shape)[:-1]
        rays = np.concatenate([np.broadcast_to(o, shape + (3,)), np.broadcast_to(d, shape + (3,))], -1)
        ans = self._scene.cast_rays(o3d.core.Tensor(np.ascontiguousarray(rays.reshape(-1, 6), dtype=np.float32)))
        t = ans["t_hit"].numpy().reshape(shape)
        ids = ans["primitive_ids"].numpy().astype(np.int64).reshape(shape)
        ids[~np.isfinite(t)] = INVALID
        return RayHits(t, ids, ans["primitive_uvs"].numpy().reshape(shape + (2,)),
                       ans["primitive_normals"].numpy().reshape(shape + (3,)))

    def closest_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest surface point (float32 (N,3)), its face (int64) and barycentric uv (float32 (N,2))
        for each of ``points`` (N,3)."""
        import open3d as o3d

        ans = self._scene.compute_closest_points(o3d.core.Tensor(np.ascontiguousarray(points, np.float32)))
        return ans["points"].numpy(), ans["primitive_ids"].numpy().astype(np.int64), ans["primitive_uvs"].numpy()

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance (float32) from each of ``points`` (N,3) to the surface."""
        import open3d as o3d

        return self._scene.compute_distance(o3d.core.Tensor(np.ascontiguousarray(points, np.float32))).numpy()

    def render(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int, frame_id: str = "") -> RasterResult:
        """Render one view; ``K`` is for a ``width`` x ``height`` image."""
        origin, dirs = pixel_rays(K, c2w, width, height)
        hits = self.cast_rays(origin, dirs)
        hit = np.isfinite(hits.t)
        face_ids = np.where(hit, hits.face_ids, INVALID).astype(np.int32)
        depth = np.where(hit, hits.t, 0.0).astype(np.float32)
        return RasterResult(frame_id, face_ids, depth)

    def render_frame(self, frame: Frame, intrinsics: Intrinsics | None = None) -> RasterResult:
        """Render ``frame`` at ``intrinsics`` (default: the frame's RGB intrinsics)."""
        intr = intrinsics or frame.intrinsics
        return self.render(intr.K, frame.c2w, intr.width, intr.height, frame.frame_id)

    def render_frames(self, frames: Iterable[Frame], width: int | None = None) -> Iterator[RasterResult]:
        """Stream buffers frame by frame (never all in memory); optional working width rescales K."""
        for f in frames:
            intr = f.intrinsics
            if width is not None and width != intr.width:
                intr = intr.scaled(width, round(intr.height * width / intr.width))
            yield self.render_frame(f, intr)

    def first_hit(self, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distance along (unit) rays to the first hit (inf if none) and the face id (-1 if none)."""
        hits = self.cast_rays(origins, directions)
        return hits.t, hits.face_ids
