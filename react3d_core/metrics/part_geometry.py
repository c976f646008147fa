"""How much of a part's front its exported geometry covers.

A part found in the images on a plane the depth sensor missed gets its surface from the completed scan
(a slab over the missed region). A part whose mesh is a sliver of its rectangle still exports and moves,
but a robot reaching for it finds nothing there, so "exported with geometry" is measured as cover: the
share of the front's rectangle that the part mesh occupies seen along the front's normal.
"""

from __future__ import annotations

import numpy as np

from ..data.mesh import TriMesh
from ..raster.rasterizer import Rasterizer


def front_frame(axes: np.ndarray, extents: np.ndarray, front_normal: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The front's in-plane axes and sizes from an oriented box: the box axis most parallel to the front
    normal is the thickness; the other two span the front (returned ``u, v, width, height``)."""
    axes = np.asarray(axes, float).reshape(3, 3)
    extents = np.asarray(extents, float).reshape(3)
    n = np.asarray(front_normal, float) / np.linalg.norm(front_normal)
    k = int(np.argmax(np.abs(axes @ n)))
    i, j = (a for a in range(3) if a != k)
    return axes[i], axes[j], float(extents[i]), float(extents[j])


def front_cover(mesh: TriMesh, center: np.ndarray, normal: np.ndarray, u: np.ndarray, v: np.ndarray,
                width: float, height: float, cell: float = 0.01, reach: float = 0.25) -> float:
    """Share of the ``width`` x ``height`` rectangle around ``center`` (spanned by unit ``u``, ``v``) whose
    ray along ``-normal``, started ``reach`` in front of it, meets ``mesh`` within ``2 * reach``.

    Rays sit at the centres of a ``cell`` grid, so a mesh covering the left half of the rectangle gives
    0.5 whatever its tessellation; surface far behind the rectangle (another part, the wall) is beyond
    the reach and does not count.
    """
    if mesh.n_faces == 0 or width <= 0 or height <= 0:
        return 0.0
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    nu, nv = max(1, int(round(width / cell))), max(1, int(round(height / cell)))
    su = (np.arange(nu) + 0.5) / nu * width - width / 2
    sv = (np.arange(nv) + 0.5) / nv * height - height / 2
    gu, gv = np.meshgrid(su, sv, indexing="ij")
    pts = np.asarray(center, float) + gu.reshape(-1, 1) * np.asarray(u, float) + gv.reshape(-1, 1) * np.asarray(v, float)
    origins = pts + reach * n
    hits = Rasterizer(mesh).cast_rays(origins, -n)
    return float(np.mean(hits.t <= 2 * reach))
