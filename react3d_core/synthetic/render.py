"""Render synthetic RGB-D frames by ray casting: shaded RGB, sensor-like depth, GT part-id images.

RGB colours are vertex colours interpolated barycentrically at the hit (Open3D returns the hit's
barycentric uv), shaded with a head light plus a ceiling light (``realism="plain"``; the photo-like
renderer is :mod:`.materials`). Depth is rendered at the iPhone
LiDAR size and degraded like a sensor: relative noise, drop-outs at depth discontinuities and
random holes, all from a seeded generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..camera import K_SIZE
from ..data.mesh import TriMesh
from ..raster import Rasterizer, pixel_rays

RGB_SIZE = (960, 720)
DEPTH_SIZE = (256, 192)


def base_intrinsics(rng: np.random.Generator) -> np.ndarray:
    """iPhone-like K for 1920x1440 with a slightly off-centre principal point."""
    f = float(rng.uniform(1420, 1480))
    return np.array([[f, 0, 960 + rng.uniform(-8, 8)], [0, f, 720 + rng.uniform(-8, 8)], [0, 0, 1]])


def scale_K(K: np.ndarray, width: int) -> np.ndarray:
    s = width / K_SIZE[0]
    out = K.copy()
    out[:2] *= s
    return out


@dataclass
class RayCaster:
    """Per-pixel hits on one mesh (its :class:`~react3d_core.raster.Rasterizer`, built once, reused for
    all frames) and the colours shaded from them."""

    mesh: TriMesh

    def __post_init__(self) -> None:
        self._raster = Rasterizer(self.mesh)
        self._colors = self.mesh.colors.astype(np.float32)

    def cast(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int) -> dict[str, np.ndarray]:
        """Per pixel: z-depth (inf = miss), face id (-1), barycentric uv, unit ray direction, face normal,
        world hit point (0 where nothing is hit)."""
        origin, dw = pixel_rays(K, c2w, width, height)  # the Rasterizer's pixel convention
        h = self._raster.cast_rays(origin, dw)
        hit = np.isfinite(h.t)
        point = np.where(hit[..., None], origin + np.where(hit, h.t, 0.0)[..., None] * dw, 0.0)
        return {"depth": h.t, "face": h.face_ids, "uv": h.uvs, "normal": h.normals,
                "dir": dw / np.linalg.norm(dw, axis=-1, keepdims=True), "point": point.astype(np.float32)}

    def rgb(self, hit: dict[str, np.ndarray], rng: np.random.Generator) -> np.ndarray:
        """Shaded colour image (uint8 RGB); misses are black."""
        face = hit["face"]
        ok = face >= 0
        f = self.mesh.faces[face[ok]]
        uv = hit["uv"][ok]
        c = self._colors
        u, v = uv[:, :1], uv[:, 1:]
        col = c[f[:, 0]] * (1.0 - u - v) + c[f[:, 1]] * u + c[f[:, 2]] * v
        n = hit["normal"][ok]
        d = hit["dir"][ok].astype(np.float32)
        light = np.array([0.3, -0.2, 0.93], np.float32) / np.float32(np.linalg.norm([0.3, -0.2, 0.93]))
        shade = 0.35 + 0.5 * np.abs(np.einsum("ij,ij->i", n, d)) + 0.2 * np.clip(n @ light, 0, None)
        img = np.zeros(face.shape + (3,), np.float32)
        img[ok] = col * shade[:, None]
        img += rng.standard_normal(img.shape, dtype=np.float32) * np.float32(2.0)
        return np.clip(img, 0, 255).astype(np.uint8)


def sensor_depth(depth: np.ndarray, rng: np.random.Generator, max_range: float = 8.0) -> np.ndarray:
    """Degrade a clean z-depth like a phone LiDAR: noise, edge drop-outs, holes; 0 = no reading."""
    d = np.where(np.isfinite(depth), depth, 0.0).astype(np.float64)
    valid = (d > 0) & (d < max_range)
    noisy = d * (1.0 + rng.normal(0.0, 0.004, d.shape)) + rng.normal(0.0, 0.002, d.shape)
    pad = np.pad(d, 1, mode="edge")
    win = np.stack([pad[i:i + d.shape[0], j:j + d.shape[1]] for i in range(3) for j in range(3)])
    edge = (win.max(0) - win.min(0)) > 0.06
    drop = (edge & (rng.random(d.shape) < 0.6)) | (rng.random(d.shape) < 0.005)
    return np.where(valid & ~drop, noisy, 0.0).astype(np.float32)
