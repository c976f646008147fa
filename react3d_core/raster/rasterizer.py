"""Triangle-id and depth buffers by ray casting (Open3D/Embree) through pixel centres.

Ray casting is exact for any principal point and image size: a pixel (u, v) looks along
K^-1 [u, v, 1], so there is no projection-matrix sign convention to get wrong (the reference's
OpenGL path had a principal-point sign error). ``depth`` is the z-depth along the optical axis.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from ..data.frames import Frame, Intrinsics
from ..data.mesh import TriMesh

INVALID = -1


@dataclass
class RasterResult:
    """One frame's buffers: ``face_ids`` int32 (H, W) with -1 for background; ``depth`` float32 metres (0 = none)."""

    frame_id: str
    face_ids: np.ndarray
    depth: np.ndarray


class Rasterizer:
    """Holds the mesh in an Embree BVH once; renders any number of views."""

    def __init__(self, mesh: TriMesh, n_threads: int = 0) -> None:
        import open3d as o3d

        self.mesh = mesh
        self._scene = o3d.t.geometry.RaycastingScene(nthreads=n_threads)
        vt = o3d.core.Tensor(np.ascontiguousarray(mesh.vertices, dtype=np.float32))
        ft = o3d.core.Tensor(np.ascontiguousarray(mesh.faces, dtype=np.uint32))
        self._scene.add_triangles(vt, ft)

    def render(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int, frame_id: str = "") -> RasterResult:
        """Render one view; ``K`` is for a ``width`` x ``height`` image."""
        import open3d as o3d

        u, v = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
        dc = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1)
        R = c2w[:3, :3].astype(np.float32)
        dw = dc @ R.T  # not normalised: t_hit is then the z-depth directly
        rays = np.concatenate([np.broadcast_to(c2w[:3, 3].astype(np.float32), dw.shape), dw], -1)
        ans = self._scene.cast_rays(o3d.core.Tensor(np.ascontiguousarray(rays.reshape(-1, 6), dtype=np.float32)))
        t = ans["t_hit"].numpy().reshape(height, width)
        ids = ans["primitive_ids"].numpy().reshape(height, width).astype(np.int64)
        hit = np.isfinite(t)
        face_ids = np.where(hit, ids, INVALID).astype(np.int32)
        depth = np.where(hit, t, 0.0).astype(np.float32)
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
        import open3d as o3d

        rays = np.concatenate([np.asarray(origins, np.float32), np.asarray(directions, np.float32)], -1)
        ans = self._scene.cast_rays(o3d.core.Tensor(np.ascontiguousarray(rays.reshape(-1, 6), dtype=np.float32)))
        t = ans["t_hit"].numpy()
        ids = ans["primitive_ids"].numpy().astype(np.int64)
        ids[~np.isfinite(t)] = INVALID
        return t, ids
