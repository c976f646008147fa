"""Tessellation variants of a scan mesh (quadric decimation to a face count or share, vertex clustering):
the same surface and colours in other triangles."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.data.mesh import TriMesh
from react3d_core.raster import Rasterizer
from react3d_core.synthetic.remesh import cluster_vertices, decimate_to


def _bumpy_sheet(step: float = 0.01) -> TriMesh:
    """A 1 m x 1 m sheet at y = 0 on a ``step`` grid with a 5 cm x 40 cm bar 3 cm proud (a handle), red
    left of x = 0.5 and blue right of it."""
    xs = np.arange(0.0, 1.0 + 1e-9, step)
    X, Z = np.meshgrid(xs, xs)
    bar = (np.abs(X - 0.3) <= 0.025) & (np.abs(Z - 0.5) <= 0.2)
    v = np.stack([X.ravel(), np.where(bar, -0.03, 0.0).ravel(), Z.ravel()], 1)
    n = len(xs)
    i = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None]).ravel()
    f = np.concatenate([np.stack([i, i + 1, i + n + 1], 1), np.stack([i, i + n + 1, i + n], 1)])
    col = np.where((v[:, 0] < 0.5)[:, None], [200, 0, 0], [0, 0, 200]).astype(np.uint8)
    return TriMesh(v, f, col)


@pytest.mark.parametrize("make, n_max", [(lambda m: decimate_to(m, 2000), 2200), (lambda m: decimate_to(m, 0.1), 2200),
                                         (lambda m: cluster_vertices(m, 0.02), 6000)])
def test_variants_keep_the_surface_and_its_colours(make, n_max: int) -> None:  # noqa: ANN001
    """The 20k-face sheet re-made in at most ``n_max`` faces: every new vertex within 1 cm of the old
    surface (on it, for the quadric), every old vertex within 1.5 cm of the new one, and each new vertex
    coloured like its side."""
    mesh = _bumpy_sheet()
    new = make(mesh)
    assert 0 < new.n_faces <= n_max < mesh.n_faces
    assert Rasterizer(mesh).distance(new.vertices.astype(np.float32)).max() <= 0.01
    assert Rasterizer(new).distance(mesh.vertices.astype(np.float32)).max() <= 0.015
    away = np.abs(new.vertices[:, 0] - 0.5) > 0.03
    red = new.vertices[:, 0] < 0.5
    assert np.array_equal(new.colors[away & red], np.tile([200, 0, 0], ((away & red).sum(), 1)))
    assert np.array_equal(new.colors[away & ~red], np.tile([0, 0, 200], ((away & ~red).sum(), 1)))


def test_variants_refuse_what_makes_no_mesh() -> None:
    mesh = _bumpy_sheet(0.1)
    with pytest.raises(ValueError, match="positive"):
        decimate_to(mesh, 0)
    with pytest.raises(ValueError, match="positive"):
        cluster_vertices(mesh, 0.0)
    assert decimate_to(mesh, 1.0) is mesh and decimate_to(mesh, 10 ** 6) is mesh
