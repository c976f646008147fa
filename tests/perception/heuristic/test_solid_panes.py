"""Framed holes the scan holds a surface across are solid panels, not glass panes (hand-made grids and meshes).

A raised panel's tilted middle is no part of its plane and its bevels frame it all round, as a glass
door's frame rings its pane; glass leaves no surface near the plane, a panel leaves it all."""

from __future__ import annotations

import numpy as np

from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.image_fronts import solid_panes

from tests.perception.heuristic.flat_orthos import flat_ortho

RES = 0.004
ROWS, COLS = slice(60, 100), slice(100, 160)  # the hole: x 0.40-0.64 m, z 0.40-0.56 m on the plane y = 0


def sheet(x0: float, x1: float, z0: float, z1: float, y: float, n: int) -> TriMesh:
    """An n x n grid of triangle pairs over [x0, x1] x [z0, z1] at depth ``y``, facing -y (out of the plane)."""
    xs, zs = np.linspace(x0, x1, n + 1), np.linspace(z0, z1, n + 1)
    gx, gz = np.meshgrid(xs, zs)
    v = np.stack([gx.ravel(), np.full(gx.size, y), gz.ravel()], 1)
    k = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1)
    a, b, c, d = k[:-1, :-1].ravel(), k[:-1, 1:].ravel(), k[1:, 1:].ravel(), k[1:, :-1].ravel()
    return TriMesh(v, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]))


def pyramid(x0: float, x1: float, z0: float, z1: float, rise: float) -> TriMesh:
    """A pyramid panel over the rectangle: four facets from its edges (y = 0) to its apex ``rise`` m proud."""
    apex = [(x0 + x1) / 2, -rise, (z0 + z1) / 2]
    v = np.array([[x0, 0, z0], [x1, 0, z0], [x1, 0, z1], [x0, 0, z1], apex], float)
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return TriMesh(v, f)


def hole() -> tuple[np.ndarray, object]:
    panes = np.zeros((200, 300), bool)
    panes[ROWS, COLS] = True
    return panes, flat_ortho(np.ones((200, 300, 3)), RES)


def test_a_panel_across_the_hole_is_solid_at_any_tessellation_and_glass_is_not():
    panes, o = hole()
    for n in (1, 4, 30):  # two triangles (a decimated scan) or fine ones: the same answer
        glass, solid = solid_panes(panes, o, sheet(0.40, 0.64, 0.40, 0.56, -0.01, n), 0.015, 0.5)
        assert not glass.any() and np.array_equal(solid, panes)
    # what stands behind the glass (a shelf 6 cm back) or a surface facing into the plane is no panel
    for mesh in (sheet(0.40, 0.64, 0.40, 0.56, 0.06, 8),
                 TriMesh(sheet(0.40, 0.64, 0.40, 0.56, 0.0, 8).vertices, sheet(0.40, 0.64, 0.40, 0.56, 0.0, 8).faces[:, ::-1])):
        glass, solid = solid_panes(panes, o, mesh, 0.015, 0.5)
        assert np.array_equal(glass, panes) and not solid.any()


def test_a_pyramid_panel_is_solid_a_partly_held_hole_follows_the_share():
    panes, o = hole()
    glass, solid = solid_panes(panes, o, pyramid(0.40, 0.64, 0.40, 0.56, 0.012), 0.015, 0.5)
    assert np.array_equal(solid, panes) and not glass.any()
    # a surface over 40 % of the hole (a jar behind the glass at the frame's depth): glass at share 0.5 ...
    part = sheet(0.40, 0.496, 0.40, 0.56, 0.0, 6)
    glass, solid = solid_panes(panes, o, part, 0.015, 0.5)
    assert np.array_equal(glass, panes) and not solid.any()
    # ... solid at share 0.3; share 1 turns the rule off
    assert np.array_equal(solid_panes(panes, o, part, 0.015, 0.3)[1], panes)
    glass, solid = solid_panes(panes, o, sheet(0.40, 0.64, 0.40, 0.56, 0.0, 4), 0.015, 1.0)
    assert np.array_equal(glass, panes) and not solid.any()


def test_each_hole_is_judged_on_its_own():
    panes, o = hole()
    panes[120:160, 100:160] = True  # a second hole below: x 0.40-0.64, z 0.16-0.32, with nothing across it
    glass, solid = solid_panes(panes, o, sheet(0.40, 0.64, 0.40, 0.56, 0.005, 5), 0.015, 0.5)
    assert solid[ROWS, COLS].all() and solid.sum() == 40 * 60
    assert glass[120:160, 100:160].all() and glass.sum() == 40 * 60
