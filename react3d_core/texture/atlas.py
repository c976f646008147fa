"""UV atlases: xatlas charts for small meshes, a per-triangle cell atlas for large scans.

Pixel convention used throughout the texture stage: ``px`` = (x right, y down) in texels, texel
(i, j) has its centre at (i + 0.5, j + 0.5); the written UV is (x / W, 1 - y / H) (OpenGL/OBJ v up).
"""

from __future__ import annotations

import math

import numpy as np

from ..config.export import ExportConfig

ATLAS_FILL = 0.7
"""Typical fraction of an xatlas atlas covered by charts: the texel budget is divided by it."""


def texture_side(area_m2: float, config: ExportConfig) -> int:
    """Texture side from a texel budget: ``texel_per_m`` texels per metre over the surface.

    side = texel_per_m * sqrt(area / ATLAS_FILL), rounded up to a multiple of 4, clamped to
    [min_texture, max_texture]. Why: a fixed size wastes memory on a handle and blurs a wall.
    """
    side = config.texel_per_m * math.sqrt(max(area_m2, 0.0) / ATLAS_FILL)
    side = int(math.ceil(side / 4.0) * 4)
    return int(min(max(side, config.min_texture), config.max_texture))


def xatlas_atlas(vertices: np.ndarray, faces: np.ndarray, side: int, padding: int = 2) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int]:
    """Chart-based atlas from xatlas (seam-minimising, area-preserving).

    Returns (vertex_map into the input vertices, new faces, uv pixel coords (x right, y down), W, H).
    xatlas is slow (~3 s per 20k faces here) and crashed above ~80k faces in our measurements, so it is
    used for parts/bases only (``ExportConfig.xatlas_max_faces``).
    """
    import xatlas

    atlas = xatlas.Atlas()
    atlas.add_mesh(np.ascontiguousarray(vertices, np.float32), np.ascontiguousarray(faces, np.uint32))
    pack = xatlas.PackOptions()
    pack.resolution = int(side)
    pack.padding = int(padding)
    pack.bilinear = True
    atlas.generate(pack_options=pack)
    vmap, new_faces, uv = atlas[0]
    W, H = int(atlas.width), int(atlas.height)
    px = np.empty((len(uv), 2), np.float64)
    px[:, 0] = uv[:, 0] * W
    px[:, 1] = (1.0 - uv[:, 1]) * H
    return np.asarray(vmap, np.int64), np.asarray(new_faces, np.int64), px, W, H


def cell_size(n_faces: int, mean_face_area: float, config: ExportConfig) -> int:
    """Cell side (texels) giving each triangle ~texel_per_m density in half a cell, >= 3, capped by max_texture."""
    cols = max(1, math.ceil(math.sqrt(math.ceil(n_faces / 2))))
    want = math.ceil(config.texel_per_m * math.sqrt(2.0 * max(mean_face_area, 0.0)))
    cap = config.max_texture // cols
    return int(max(3, min(want, cap)))


def cell_atlas(n_faces: int, s: int) -> tuple[np.ndarray, int, int, int]:
    """Per-triangle atlas (simplified path for large scans): two triangles per s x s cell.

    Triangle A of a cell has corners at texel centres (0.5,0.5), (s-1.5,0.5), (0.5,s-1.5); triangle B at
    (s-.5,s-.5), (1.5,s-.5), (s-.5,1.5); the diagonal between them is one texel wide. Corners sit on
    texel centres, so sampling at a vertex returns exactly the baked vertex colour. Returns
    (corner px (M,3,2), W, H, cols). O(M) and fully vectorized, unlike chart atlases.
    """
    if s < 3:
        raise ValueError("cell size must be >= 3 texels")
    cells = max(1, math.ceil(n_faces / 2))
    cols = max(1, math.ceil(math.sqrt(cells)))
    rows = math.ceil(cells / cols)
    f = np.arange(n_faces)
    c = f // 2
    origin = np.stack([(c % cols) * s, (c // cols) * s], axis=1).astype(np.float64)
    canon = np.array(
        [[[0.5, 0.5], [s - 1.5, 0.5], [0.5, s - 1.5]], [[s - 0.5, s - 0.5], [1.5, s - 0.5], [s - 0.5, 1.5]]], np.float64
    )
    corners = origin[:, None, :] + canon[f % 2]
    return corners, cols * s, rows * s, cols


def cell_weights(s: int) -> tuple[np.ndarray, np.ndarray]:
    """Per texel of a cell: which triangle (0 = A, 1 = B) and its barycentric weights (s*s, 3), extrapolated."""
    j, i = np.mgrid[0:s, 0:s]
    x = i.ravel() + 0.5
    y = j.ravel() + 0.5
    slot = (x + y > s).astype(np.int64)  # ties (x + y == s) go to A
    canon = np.array(
        [[[0.5, 0.5], [s - 1.5, 0.5], [0.5, s - 1.5]], [[s - 0.5, s - 0.5], [1.5, s - 0.5], [s - 0.5, 1.5]]], np.float64
    )
    tri = canon[slot]  # (T,3,2)
    d = np.stack([x, y], 1) - tri[:, 0]
    e1 = tri[:, 1] - tri[:, 0]
    e2 = tri[:, 2] - tri[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    l1 = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / det
    l2 = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / det
    return slot, np.stack([1 - l1 - l2, l1, l2], 1)
