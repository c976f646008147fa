"""What the image path knows of a plane from the scan surface (rays cast along its normal, points spread
over its faces) is the same however the surface is triangulated."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import HandleConfig, PlanesConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.image_fronts import protrusion_map
from react3d_core.perception.heuristic.orthophoto import Orthophoto
from react3d_core.perception.heuristic.plane_surface import cast_surface, flat_surface
from react3d_core.perception.heuristic.planes import Plane, surface_samples
from react3d_core.raster import Rasterizer


def test_surface_samples_hand_computed() -> None:
    """Spacing 2 cm: a right triangle with 10 cm legs (longest edge 14.1 cm) is a lattice of
    ceil(14.1 / 2) = 8 steps, 9 * 10 / 2 = 45 points (its vertices among them); a triangle with 2.5 cm legs
    (3.5 cm edge: 2 steps, at most twice the spacing) is its centroid; one with 3 cm legs (4.2 cm edge) a
    lattice of 3 steps, 10 points. Each face's area is shared by its points."""
    big = np.array([[0.0, 0, 0], [0.1, 0, 0], [0, 0, 0.1]])
    small = np.array([[1.0, 0, 0], [1.025, 0, 0], [1.0, 0, 0.025]])
    mid = np.array([[2.0, 0, 0], [2.03, 0, 0], [2.0, 0, 0.03]])
    pts, face, wt = surface_samples(np.stack([big, small, mid]), np.array([0.005, 0.0003125, 0.00045]), 0.02)
    assert (face == 0).sum() == 45 and (face == 1).sum() == 1 and (face == 2).sum() == 10
    assert np.allclose(pts[face == 1], [[1.025 / 3 + 2 / 3, 0, 0.025 / 3]])
    for corner in big:
        assert np.isclose(np.linalg.norm(pts[face == 0] - corner, axis=1).min(), 0)
    assert np.allclose(wt[face == 0], 0.005 / 45) and np.isclose(wt[face == 1], 0.0003125)
    assert np.allclose(wt[face == 2], 0.000045)
    # neighbouring lattice points lie one step (10 cm / 8) apart along the legs
    on_leg = np.sort(pts[(face == 0) & np.isclose(pts[:, 2], 0)][:, 0])
    assert np.allclose(np.diff(on_leg), 0.1 / 8)


def test_flat_surface_keeps_gentle_slopes_only() -> None:
    """Offsets rising 5 degrees across the grid are flat (12 degree tolerance); a 20 degree ramp is not;
    pixels without a surface are never flat. 4 mm px, 1.2 cm window."""
    res = 0.004
    cols = np.arange(60) * res
    gentle = np.tile(cols * np.tan(np.radians(5)), (40, 1)).astype(np.float32)
    steep = np.tile(cols * np.tan(np.radians(20)), (40, 1)).astype(np.float32)
    gentle[10:20, 10:20] = np.nan
    assert flat_surface(gentle, res, 0.012, 12.0).sum() == np.isfinite(gentle).sum()
    assert not flat_surface(steep, res, 0.012, 12.0).any()


def _sheet(x0: float, x1: float, z0: float, z1: float, y: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """A vertical sheet at ``y`` facing -y, triangulated on a ``step`` grid."""
    xs = np.linspace(x0, x1, max(2, int(round((x1 - x0) / step)) + 1))
    zs = np.linspace(z0, z1, max(2, int(round((z1 - z0) / step)) + 1))
    X, Z = np.meshgrid(xs, zs)
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], 1)
    nx = len(xs)
    i = (np.arange(len(zs) - 1)[:, None] * nx + np.arange(nx - 1)[None]).ravel()
    return v, np.concatenate([np.stack([i, i + 1, i + nx + 1], 1), np.stack([i, i + nx + 1, i + nx], 1)])


def _wall_with_bar(step: float) -> TriMesh:
    """A 1 m x 0.8 m wall at y = 0 and, 3 cm in front of it, the face of a 2 cm x 20 cm bar; both
    triangulated on a ``step`` grid (the bar's face at least in two triangles)."""
    vw, fw = _sheet(0.0, 1.0, 0.0, 0.8, 0.0, step)
    vb, fb = _sheet(0.5, 0.52, 0.3, 0.5, -0.03, step)
    return TriMesh(np.concatenate([vw, vb]), np.concatenate([fw, fb + len(vw)]),
                   np.full((len(vw) + len(vb), 3), 128, np.uint8))


@pytest.mark.parametrize("coarse", [0.2, 1.0])
def test_cast_surface_is_the_same_on_any_tessellation(coarse: float) -> None:
    """The wall with its bar meshed at 1 cm and in faces of ``coarse`` m (a decimated scan; at 1 m the wall
    is two triangles): the same pixels are covered and flat, the same bar stands out of the plane, and
    the surface samples span the same extent (to a centimetre). Face centroids splatted on the 4 mm grid, as before,
    would cover under 1 % of the coarse wall."""
    res = 0.004
    h, w = 200, 250
    plane = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.zeros(0, np.int64), (0.0, 1.0),
                  (0.0, 0.8), 0.8)
    o = Orthophoto(plane, np.ones((h, w, 3), np.float32), np.full((h, w), 5, np.int32), 0.0, 0.8, res)
    cfg, hc = PlanesConfig(), HandleConfig()
    maps = []
    for step in (0.01, coarse):
        mesh = _wall_with_bar(step)
        surf = cast_surface(o.grid_points(), plane.n, Rasterizer(mesh), cfg.offset_tol, hc.protrusion_depth[1],
                            cfg.offset_tol)
        flat = flat_surface(surf.offset, res, cfg.slope_win, cfg.angle_tol_deg)
        bars = protrusion_map(o, surf, hc, hc.background_win, cfg.offset_tol)
        tri = mesh.vertices[mesh.faces]
        area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        pts, _, _ = surface_samples(tri, area, cfg.cell / 2)
        maps.append((np.isfinite(surf.offset), flat, bars, pts[:, 0].min(), pts[:, 0].max()))
    (seen1, flat1, bar1, lo1, hi1), (seen2, flat2, bar2, lo2, hi2) = maps
    assert seen1.all() and flat1.mean() > 0.97  # the bar hides nothing: the plane cast ends before it
    assert np.array_equal(seen1, seen2) and np.array_equal(flat1, flat2)
    rows, cols = np.nonzero(bar1)
    assert 0.5 - res <= cols.min() * res and (cols.max() + 1) * res <= 0.52 + 2 * res  # the bar, 1 px grown
    assert np.array_equal(bar1, bar2)
    for lo, hi in ((lo1, hi1), (lo2, hi2)):  # small faces are their centroid: within a face of the edge
        assert 0.0 <= lo <= 0.01 and 0.99 <= hi <= 1.0
