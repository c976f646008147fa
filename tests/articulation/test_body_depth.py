"""Drawer travel bounded by the furniture's own depth when nothing is seen behind it.

A free-standing chest in a room, as a capture of the closed chest leaves it: top and side boards are
observed, its back and insides never are (culled), so a ray into the cavity flies to the room wall 2 m
away. Before d_body the drawer got max_depth_m - margin = 1.18 m of travel in a 0.37 m chest.
"""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.articulation.limits import set_limits
from react3d_core.assembly.scene import _Geometry
from react3d_core.cavity import PartFrame, d_body, d_hit, estimate_cavity
from react3d_core.config import CavityConfig, LimitConfig
from react3d_core.data.parts import Articulation
from react3d_core.synthetic.builder import MeshBuilder

T = 0.018  # board thickness


def chest_in_room(depth: float, back_board: bool = False):  # noqa: ANN201
    """Chest 0.6 wide, 0.8 high, carcass from y = 0 to y = ``depth``; front plane y = 0; a drawer slab in
    front (y in [-0.02, -0.002]); room: floor z = 0, ceiling z = 2.5, back wall at y = 2.6."""
    m = MeshBuilder(edge=0.1)
    grey = (200, 200, 200)
    m.add_box([0, 0, 0.8 - T], [0.6, depth, 0.8], grey)               # top
    m.add_box([0, 0, 0], [T, depth, 0.8 - T], grey)                   # sides
    m.add_box([0.6 - T, 0, 0], [0.6, depth, 0.8 - T], grey)
    if back_board:
        m.add_box([T, depth - T, 0], [0.6 - T, depth, 0.8 - T], grey)
    m.add_box([-2.0, -2.0, -0.02], [3.0, 2.6, 0.0], grey)             # floor
    m.add_box([-2.0, 2.6, 0.0], [3.0, 2.62, 2.5], grey)               # back wall
    m.add_box([-2.0, -2.0, 2.5], [3.0, 2.6, 2.52], grey)              # ceiling
    m.add_box([T + 0.002, -0.02, 0.3], [0.6 - T - 0.002, -0.002, 0.5], (150, 90, 60), key="drawer")
    mesh, _, _ = m.build()
    return mesh


def drawer_frame() -> PartFrame:
    """Drawer front: centre (0.3, -0.011, 0.4), back face at y = -0.002, normal +y into the chest."""
    return PartFrame(center=np.array([0.3, -0.011, 0.4]), u=np.array([1.0, 0.0, 0.0]), v=np.array([0.0, 0.0, 1.0]),
                     n=np.array([0.0, 1.0, 0.0]), su=0.56, sv=0.2, thickness=0.018)


def test_body_depth_of_a_chest_with_an_unseen_back() -> None:
    mesh = chest_in_room(0.37)
    geo, pf, cfg = _Geometry(mesh), drawer_frame(), CavityConfig()
    assert d_hit(pf, geo.cast, cfg) > 2.0  # the ray into the cavity reaches the room wall
    # up-rays from y = -0.002 + c hit the top board while y <= 0.37, i.e. c <= 0.372; samples at
    # c = 0.036 + 0.02 k: the last inside is 0.356, the first outside 0.376 -> body ends at 0.376 - 0.01
    assert d_body(pf, geo.cast, cfg) == pytest.approx(0.366, abs=1e-9)
    d, src, terms = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, cfg)
    assert src == "body" and d == pytest.approx(0.366, abs=1e-9) and terms["hit"] > 2.0


@pytest.mark.parametrize("depth", [0.25, 0.37, 0.6])
def test_drawer_travel_never_exceeds_the_chest_depth(depth: float) -> None:
    mesh = chest_in_room(depth)
    geo, pf = _Geometry(mesh), drawer_frame()
    d, _, _ = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, CavityConfig())
    a = Articulation(joint_type="prismatic", axis=(0.0, 1.0, 0.0), origin=(0.3, -0.011, 0.4), lower=0.0, upper=1.0)
    pts = np.array([[x, -0.011, z] for x in (0.05, 0.55) for z in (0.32, 0.48)])
    lim = set_limits(a, pts, pf.n, d, None, LimitConfig())
    assert lim.axis == pytest.approx((0.0, -1.0, 0.0))  # q > 0 pulls the drawer out of the chest
    # the chest reaches depth + 0.002 behind the slab's back face: travel stays inside it, within a step
    assert depth + 0.002 - 0.05 <= lim.upper <= depth + 0.002


def test_a_back_board_or_wall_still_sets_the_depth() -> None:
    """Where the back is seen, d_hit (the back board, nearer than where the body ends) stays the bound."""
    mesh = chest_in_room(0.37, back_board=True)
    geo, pf = _Geometry(mesh), drawer_frame()
    d, src, terms = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, CavityConfig())
    assert src == "hit" and d == pytest.approx(0.37 - T + 0.002, abs=1e-4) and terms["body"] > d


def test_no_carcass_top_gives_no_body_bound() -> None:
    """A drawer with nothing above it but the ceiling (top board unseen): no profile to follow -> inf."""
    m = MeshBuilder(edge=0.1)
    m.add_box([-2.0, -2.0, 2.5], [3.0, 2.6, 2.52], (200, 200, 200))
    mesh, _, _ = m.build()
    assert d_body(drawer_frame(), _Geometry(mesh).cast, CavityConfig()) == np.inf


def test_wall_cabinet_with_an_unseen_wall_is_bounded_from_below() -> None:
    """A wall cabinet (bottom board seen from below, top and the wall behind it never seen) over a
    floor: up-rays find nothing, down-rays hit its bottom board inside and the floor past its back."""
    m = MeshBuilder(edge=0.1)
    m.add_box([0, 0, 1.4], [0.6, 0.33, 1.4 + T], (200, 200, 200))    # bottom board, 0.33 deep
    m.add_box([-2.0, -2.0, -0.02], [3.0, 2.6, 0.0], (200, 200, 200))  # floor
    mesh, _, _ = m.build()
    pf = PartFrame(center=np.array([0.3, -0.011, 1.75]), u=np.array([1.0, 0.0, 0.0]), v=np.array([0.0, 0.0, 1.0]),
                   n=np.array([0.0, 1.0, 0.0]), su=0.56, sv=0.6, thickness=0.018)
    geo = _Geometry(mesh)
    # down-rays hit the board while y = -0.002 + c <= 0.33 (c <= 0.332): last inside 0.316, first out 0.336
    assert d_body(pf, geo.cast, CavityConfig()) == pytest.approx(0.326, abs=1e-9)
    d, src, _ = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, CavityConfig())
    assert src == "body" and d == pytest.approx(0.326, abs=1e-9)
