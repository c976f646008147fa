"""Front cover of a part's mesh, computed by hand on flat squares."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.data.mesh import TriMesh
from react3d_core.metrics.part_geometry import front_cover, front_frame


def square(x0: float, x1: float, y0: float, y1: float, z: float = 0.0, split: int = 1) -> TriMesh:
    """A flat rectangle in the plane z, cut into ``split`` x ``split`` quads (tessellation must not matter)."""
    xs, ys = np.linspace(x0, x1, split + 1), np.linspace(y0, y1, split + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    verts = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)], 1)
    idx = np.arange(gx.size).reshape(split + 1, split + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return TriMesh(verts, faces)


X, Y, Z = np.eye(3)


@pytest.mark.parametrize("split", [1, 7])
def test_half_covered_rectangle(split: int) -> None:
    # the front is 0.4 x 0.2 around the origin; the mesh covers x in [-0.2, 0] (its left half) and beyond
    mesh = square(-0.5, 0.0, -0.5, 0.5, split=split)
    assert front_cover(mesh, np.zeros(3), Z, X, Y, 0.4, 0.2) == pytest.approx(0.5)


def test_quarter_covered_and_offset_plane() -> None:
    # a 0.1 x 0.1 mesh 2 cm behind a 0.2 x 0.2 front: a quarter of it, still within the reach
    mesh = square(0.0, 0.1, 0.0, 0.1, z=-0.02)
    assert front_cover(mesh, np.zeros(3), Z, X, Y, 0.2, 0.2) == pytest.approx(0.25)


def test_surface_beyond_reach_does_not_count() -> None:
    # a wall 0.6 m behind the front is not the part's geometry
    mesh = square(-1, 1, -1, 1, z=-0.6)
    assert front_cover(mesh, np.zeros(3), Z, X, Y, 0.4, 0.4) == 0.0
    assert front_cover(TriMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64)), np.zeros(3), Z, X, Y, 0.4, 0.4) == 0.0


def test_front_frame_picks_the_thickness_axis() -> None:
    # box axes: x (0.6 wide), y (0.03 thick, the normal), z (0.8 tall)
    u, v, w, h = front_frame(np.eye(3), np.array([0.6, 0.03, 0.8]), np.array([0.0, -1.0, 0.0]))
    assert (w, h) == (0.6, 0.8)
    np.testing.assert_allclose(u, X)
    np.testing.assert_allclose(v, Z)
