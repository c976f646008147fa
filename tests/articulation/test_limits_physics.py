"""Limits from physics, on hand-made scenes with hand-computed expectations: a drawer's travel never passes
the back of its furniture, a prismatic axis is the front normal unless the part is a sliding door, a
door's range ends where its swept volume meets a wall, a neighbour or the floor (and glides past what is
only beside its path, a worktop overhang), and what a part can barely move is reported blocked."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.articulation import refine_articulation
from react3d_core.articulation.limits import prismatic_travel, revolute_limit, set_limits, sweep_points
from react3d_core.articulation.sliding import front_height, sliding_agrees
from react3d_core.assembly.scene import _Geometry
from react3d_core.cavity import PartFrame, d_body, estimate_cavity
from react3d_core.config import CavityConfig, LimitConfig
from react3d_core.data.parts import Articulation
from react3d_core.articulation import fit_part
from react3d_core.synthetic.builder import MeshBuilder

T = 0.018  # board thickness
GREY = (200, 200, 200)


def _grid(x: tuple[float, float], y: float, z: tuple[float, float], nx: int = 31, nz: int = 11) -> np.ndarray:
    """Points on the plane y = ``y`` over [x0, x1] x [z0, z1]."""
    return np.stack(np.meshgrid(np.linspace(*x, nx), [y], np.linspace(*z, nz)), -1).reshape(-1, 3)


def _room(m: MeshBuilder) -> None:
    """Floor z = 0, ceiling z = 2.5, back wall at y = 2.6 (no side walls)."""
    m.add_box([-2.0, -2.0, -0.02], [3.0, 2.6, 0.0], GREY)
    m.add_box([-2.0, 2.6, 0.0], [3.0, 2.62, 2.5], GREY)
    m.add_box([-2.0, -2.0, 2.5], [3.0, 2.6, 2.52], GREY)


def _drawer_frame(z: float = 0.4) -> PartFrame:
    """Drawer front 0.56 x 0.2 centred at (0.3, -0.011, z), back face at y = -0.002, normal +y (into the body)."""
    return PartFrame(center=np.array([0.3, -0.011, z]), u=np.array([1.0, 0.0, 0.0]), v=np.array([0.0, 0.0, 1.0]),
                     n=np.array([0.0, 1.0, 0.0]), su=0.56, sv=0.2, thickness=0.018)


# --- a drawer's travel is bounded by its body depth --------------------------------------------------------------


def test_body_of_a_tall_unit_whose_top_no_camera_saw_is_found_by_its_side_panels() -> None:
    """A 0.37 m deep unit with side panels but no top board (above every camera) in a room: up-rays reach the
    ceiling inside and behind it alike (no end), so sideways rays find where its side panels end."""
    m = MeshBuilder(edge=0.1)
    m.add_box([0, 0, 0], [T, 0.37, 2.1], GREY)
    m.add_box([0.6 - T, 0, 0], [0.6, 0.37, 2.1], GREY)
    _room(m)
    mesh, _, _ = m.build()
    geo, pf, cfg = _Geometry(mesh), _drawer_frame(), CavityConfig()
    # sideways rays from (0.3, -0.002 + c, 0.4 +- 0.06) hit the panels (t = 0.282 <= 0.28 + 0.1) while
    # -0.002 + c <= 0.37; samples c = 0.036 + 0.02 k: last inside 0.356, first outside 0.376 -> 0.376 - 0.01
    assert d_body(pf, geo.cast, cfg) == pytest.approx(0.366, abs=1e-9)
    d, src, terms = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, cfg)
    assert src == "body" and d == pytest.approx(0.366, abs=1e-9)
    a = Articulation(joint_type="prismatic", axis=(0.0, 1.0, 0.0), origin=(0.3, -0.011, 0.4))
    lim = set_limits(a, _grid((0.05, 0.55), -0.011, (0.32, 0.48)), pf.n, d, None, LimitConfig(), body_depth=terms["body"])
    assert lim.upper == pytest.approx(0.366 - 0.02) and lim.limit_source == "cavity"


def test_side_panels_of_the_neighbours_are_not_the_parts_body() -> None:
    """A drawer inside a run: the nearest panels sideways stand 0.9 m away (beyond half its width + 10 cm),
    so nothing measures the body, and the hit on the room wall 2.6 m away bounds nothing: the drawer travels
    inside the default carcass, not 1.18 m."""
    m = MeshBuilder(edge=0.1)
    m.add_box([-0.6 - T, 0, 0], [-0.6, 0.37, 2.1], GREY)
    m.add_box([1.2, 0, 0], [1.2 + T, 0.37, 2.1], GREY)
    _room(m)
    mesh, _, _ = m.build()
    geo, pf, cfg = _Geometry(mesh), _drawer_frame(), CavityConfig()
    assert d_body(pf, geo.cast, cfg) == np.inf
    d, src, terms = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, cfg)
    # the ray flies to the room wall 2.6 m away, past max_depth_m (1.2): no bound, the default depth
    assert terms["hit"] > cfg.max_depth_m and src == "beyond_max" and d == pytest.approx(cfg.default_depth_m)
    a = Articulation(joint_type="prismatic", axis=(0.0, 1.0, 0.0), origin=(0.3, -0.011, 0.4))
    lim = set_limits(a, _grid((0.05, 0.55), -0.011, (0.32, 0.48)), pf.n, d, None, LimitConfig(), body_depth=terms["body"])
    # travel inside the 0.5 m default carcass: 0.5 - prismatic_margin_m (0.02)
    assert lim.upper == pytest.approx(0.48) and lim.limit_source == "cavity"


@pytest.mark.parametrize(("cavity", "body", "upper", "source"), [
    (0.50, 0.37, 0.35, "body"),     # the cavity estimate says more than the body: the body wins
    (0.30, 0.50, 0.28, "cavity"),   # a back board nearer than where the body ends
    (1.20, np.inf, 0.60, "prior"),  # body not measured: prismatic_max_m
    (0.50, None, 0.48, "cavity"),   # body not measured, a cavity within prismatic_max_m
    (0.04, np.inf, 0.04, "min"),    # shallower than prismatic_min_m: never past the back
    (0.50, 0.03, 0.03, "min"),      # ... whatever the cavity estimate says
])
def test_prismatic_travel_never_passes_the_body(cavity: float, body: float | None, upper: float, source: str) -> None:
    assert prismatic_travel(cavity, body, LimitConfig()) == (pytest.approx(upper), source)


# --- a prismatic axis is the front normal unless the part is a sliding door -----------------------------------------


def _slab(w: float, h: float, t: float = 0.02, n: int = 2000, seed: int = 0) -> np.ndarray:
    """Points on a front x in [0, w], z in [0.5, 0.5 + h], y in [0, t] (front face y = 0, facing -y)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform([0, 0, 0.5], [w, t, 0.5 + h], (n, 3))
    p[: n // 2, 1] = 0.0
    p[n // 2:, 1] = t
    return p


def _off_normal_deg(axis: tuple[float, ...], n: np.ndarray) -> float:
    return float(np.degrees(np.arccos(min(1.0, abs(float(np.dot(axis, n)))))))


def test_a_drawer_called_sliding_with_its_axis_out_of_the_front_is_pulled_out() -> None:
    """The oracle fault: a drawer's GT part with its box (0.6 wide, 0.15 high, 0.45 deep) looks flat with an
    in-plane axis, so the predictor says 'sliding' while its axis is the front normal. The in-plane snap
    would turn it 90 deg; the geometry disagrees, so the drawer is refined as a drawer."""
    fit = fit_part(_slab(0.6, 0.15), camera=np.array([0.3, -2.0, 0.6]), plane_normal=(0.0, 1.0, 0.0), flat_ratio=0.5)
    pred = Articulation(joint_type="prismatic", axis=(0.03, -1.0, 0.02), origin=(0.3, 0.0, 0.575))
    assert not sliding_agrees(pred.axis, fit.obb, fit.front_normal, "openable", 0.3)
    out = refine_articulation(pred, fit, refine=True, sliding=False)
    assert _off_normal_deg(out.axis, fit.front_normal) < 1e-6
    # what the unchecked flag did: 90 deg off the front normal
    assert _off_normal_deg(refine_articulation(pred, fit, refine=True, sliding=True).axis, fit.front_normal) == pytest.approx(90, abs=1e-3)


def test_a_drawer_shaped_front_never_slides_sideways() -> None:
    """An in-plane 'sliding' prediction on a 0.6 x 0.2 m front (lower than sliding_min_height_m = 0.3 m) or on
    a part labelled drawer is refused; a 0.6 x 0.7 m door keeps it, and so does a vertical slide."""
    drawer = fit_part(_slab(0.6, 0.2), camera=np.array([0.3, -2.0, 0.6]), plane_normal=(0.0, 1.0, 0.0), flat_ratio=0.5)
    door = fit_part(_slab(0.6, 0.7), camera=np.array([0.3, -2.0, 0.8]), plane_normal=(0.0, 1.0, 0.0), flat_ratio=0.5)
    assert front_height(drawer.obb, drawer.front_normal) == pytest.approx(0.2, abs=1e-3)
    sideways = (1.0, 0.05, 0.0)
    assert not sliding_agrees(sideways, drawer.obb, drawer.front_normal, "openable", 0.3)
    assert sliding_agrees(sideways, door.obb, door.front_normal, "openable", 0.3)
    assert not sliding_agrees(sideways, door.obb, door.front_normal, "kitchen_cabinet.drawer_3", 0.3)
    assert sliding_agrees((0.0, 0.05, 1.0), drawer.obb, drawer.front_normal, "openable", 0.3)  # a vertical slide
    # axis 40 deg from the front normal: not in the plane (> 45 deg needed)
    tilted = (np.sin(np.radians(40)), np.cos(np.radians(40)), 0.0)
    assert not sliding_agrees(tilted, door.obb, door.front_normal, "openable", 0.3)


# --- a door's range ends where its swept volume meets a wall, a neighbour, the floor ------------------------------


def _wall_geometry() -> tuple[_Geometry, np.ndarray]:
    m = MeshBuilder(edge=0.05)
    m.add_box([-0.2, -1.0, 0], [-0.1, 0.5, 1.0], GREY)  # wall plane x = -0.1, beside the hinge
    mesh, _, _ = m.build()
    return _Geometry(mesh), np.zeros(mesh.n_faces, bool)


def test_the_handle_meets_the_wall_before_the_free_edge() -> None:
    """Door x in [0.02, 0.6] on the plane y = -0.01, hinge (0, -0.01) about -z (q > 0 swings to -y), a wall
    at x = -0.1. Free edge (r = 0.6) alone: 0.6 cos q = -0.1 + 0.008 -> q = 98.8 deg. A handle tip 4 cm proud
    at x = 0.55: (0.55, -0.04) from the hinge, x(q) = R cos(q + phi) with R = |(0.55, 0.04)|, phi = atan(0.04 /
    0.55) -> q = arccos(-0.092 / R) - phi = 95.4 deg. The sweep stops at its last sample before that."""
    geo, own = _wall_geometry()
    door = _grid((0.02, 0.6), -0.01, (0.1, 0.7))
    handle = np.array([[0.55, -0.05, z] for z in np.linspace(0.35, 0.45, 5)])
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.4))
    cfg = LimitConfig(revolute_max_deg=180)
    dist = geo.distance_excluding(own, np.array([0.3, -0.01, 0.4]), np.array([0, 1.0, 0]), with_points=True)
    step = np.degrees(0.004 / 0.6)  # sweep_step_m over the farthest point's radius
    q_edge = np.degrees(np.arccos(-0.092 / 0.6))
    q, src = revolute_limit(a, door, dist, cfg)
    assert src == "sweep" and q_edge - step - 1e-6 <= np.degrees(q) <= q_edge
    R, phi = np.hypot(0.55, 0.04), np.arctan2(0.04, 0.55)
    q_handle = np.degrees(np.arccos(-0.092 / R) - phi)
    q, src = revolute_limit(a, np.concatenate([door, handle]), dist, cfg)
    assert src == "sweep" and q_handle - step - 1e-6 <= np.degrees(q) <= q_handle


def test_a_thin_neighbour_is_not_stepped_over() -> None:
    """A 4 mm rod on the free edge's path (r = 0.6) at 62 deg: 5 deg samples (5.2 cm of arc) jumped over it;
    samples that slow down to sweep_step_m = 4 mm near it stop before it."""
    m = MeshBuilder(edge=0.01)
    t = np.radians(62)
    c = np.array([0.6 * np.cos(t), -0.01 - 0.6 * np.sin(t)])
    m.add_box([c[0] - 0.002, c[1] - 0.002, 0.0], [c[0] + 0.002, c[1] + 0.002, 1.0], GREY)
    mesh, _, _ = m.build()
    dist = _Geometry(mesh).distance_excluding(np.zeros(mesh.n_faces, bool), np.array([0.3, -0.01, 0.4]),
                                               np.array([0, 1.0, 0]), with_points=True)
    door = _grid((0.02, 0.6), -0.01, (0.1, 0.7))
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.4))
    # blocked once the free edge is within 0.002 + 0.008 of the rod's centre: 0.01 / 0.6 rad before 62 deg
    stop, step = 62 - np.degrees(0.01 / 0.6), np.degrees(0.004 / 0.6)
    q, src = revolute_limit(a, door, dist, LimitConfig(revolute_max_deg=110, revolute_step_deg=5.0))
    assert src == "sweep" and stop - step - 1e-6 <= np.degrees(q) <= stop
    q, src = revolute_limit(a, door, dist, LimitConfig(revolute_max_deg=110, revolute_step_deg=5.0, sweep_step_m=0.06))
    assert src == "cap"  # what 5 deg samples did


def test_a_bottom_hinged_door_stops_above_the_floor() -> None:
    """A dishwasher-like door 0.6 m tall hinged at z = 0.1 (axis +x: q > 0 swings its top edge to -y and
    down) over a floor z = 0: its top edge reaches z = 0.008 when 0.1 + 0.6 cos q = 0.008, q = 98.8 deg."""
    m = MeshBuilder(edge=0.1)
    m.add_box([-1.0, -2.0, -0.02], [2.0, 1.0, 0.0], GREY)
    mesh, _, _ = m.build()
    dist = _Geometry(mesh).distance_excluding(np.zeros(mesh.n_faces, bool), np.array([0.3, 0.0, 0.4]),
                                               np.array([0, 1.0, 0]), with_points=True)
    door = np.stack(np.meshgrid(np.linspace(0.0, 0.6, 13), [0.0], np.linspace(0.12, 0.7, 30)), -1).reshape(-1, 3)
    a = Articulation(joint_type="revolute", axis=(1.0, 0, 0), origin=(0.3, 0.0, 0.1))
    assert a.move(np.array([[0.3, 0.0, 0.7]]), 0.1)[0, 1] < 0  # q > 0 swings out (-y)
    q, src = revolute_limit(a, door, dist, LimitConfig(revolute_max_deg=110))
    expect = np.degrees(np.arccos(-0.092 / 0.6))
    assert src == "sweep" and expect - np.degrees(0.004 / 0.6) - 1e-6 <= np.degrees(q) <= expect


def test_a_door_glides_under_a_worktop_overhang() -> None:
    """Base-unit door (top edge z = 0.85) under a worktop whose underside is 3 mm above it and overhangs the
    front by 3 cm: the worktop is beside the door's path, so the range is the cap, not the first sample."""
    m = MeshBuilder(edge=0.05)
    m.add_box([-0.2, -0.03, 0.853], [0.8, 0.6, 0.883], GREY)
    mesh, _, _ = m.build()
    geo = _Geometry(mesh)
    own = np.zeros(mesh.n_faces, bool)
    door = _grid((0.02, 0.6), -0.01, (0.1, 0.85))
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.45))
    dist = geo.distance_excluding(own, np.array([0.3, -0.02, 0.45]), np.array([0, 1.0, 0]), with_points=True)
    assert revolute_limit(a, door, dist, LimitConfig(), geo.distance_excluding(own)) == (pytest.approx(np.radians(110)), "cap")


def test_a_door_that_cannot_open_is_reported_blocked() -> None:
    """A post 3 cm in front of the free edge: the sweep stops below revolute_min_deg (15 deg). The range kept
    is the free one (the last sample before the edge comes within the clearance: 0.6 sin q = 0.03 - 0.008,
    2.1 deg), reported 'blocked'."""
    m = MeshBuilder(edge=0.02)
    m.add_box([0.5, -0.07, 0.0], [0.7, -0.04, 1.0], GREY)  # face y = -0.04: 3 cm in front of the door plane
    mesh, _, _ = m.build()
    dist = _Geometry(mesh).distance_excluding(np.zeros(mesh.n_faces, bool), np.array([0.3, -0.01, 0.4]),
                                               np.array([0, 1.0, 0]), with_points=True)
    door = _grid((0.02, 0.6), -0.01, (0.1, 0.7))
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.4))
    q, src = revolute_limit(a, door, dist, LimitConfig())
    stop = np.degrees(np.arcsin(0.022 / 0.6))
    assert src == "blocked" and stop - np.degrees(0.004 / 0.6) - 1e-6 <= np.degrees(q) <= stop


# --- a drawer's pull-out meets what stands in front of it -----------------------------------------------------------


def test_a_drawer_at_an_inside_corner_stops_before_the_other_runs_handle() -> None:
    """Drawer front x in [0, 0.6], z in [0.6, 0.8] on y = -0.02, body 0.55 deep, cavity 0.52: travel 0.5. A
    handle of the perpendicular run's door stands at y in [-0.45, -0.43] in front of it: the front face
    reaches y = -0.43 + 0.008 at s = 0.402, the sweep stops at its last sample before (samples 4 mm apart near it)."""
    m = MeshBuilder(edge=0.01)
    m.add_box([0.3, -0.45, 0.65], [0.32, -0.43, 0.75], GREY)
    m.add_box([-0.2, -0.2, 0.803], [0.8, 0.6, 0.83], GREY)  # and a worktop 3 mm above it, beside its path
    mesh, _, _ = m.build()
    geo = _Geometry(mesh)
    own = np.zeros(mesh.n_faces, bool)
    front = _grid((0.0, 0.6), -0.02, (0.6, 0.8))
    a = Articulation(joint_type="prismatic", axis=(0.0, 1.0, 0.0), origin=(0.3, -0.01, 0.7))
    dist = geo.distance_excluding(own, np.array([0.3, -0.02, 0.7]), np.array([0, 1.0, 0]), with_points=True)
    lim = set_limits(a, front, np.array([0, 1.0, 0]), 0.52, dist, LimitConfig(), geo.distance_excluding(own), body_depth=0.55)
    np.testing.assert_allclose(lim.axis, (0, -1, 0))
    assert lim.limit_source == "sweep" and 0.402 - 0.004 - 1e-6 <= lim.upper <= 0.402 + 1e-6  # float32 closest points
    # without the handle the worktop above does not stop it: the cavity's travel
    m = MeshBuilder(edge=0.01)
    m.add_box([-0.2, -0.2, 0.803], [0.8, 0.6, 0.83], GREY)
    mesh, _, _ = m.build()
    geo = _Geometry(mesh)
    own = np.zeros(mesh.n_faces, bool)
    dist = geo.distance_excluding(own, np.array([0.3, -0.02, 0.7]), np.array([0, 1.0, 0]), with_points=True)
    lim = set_limits(a, front, np.array([0, 1.0, 0]), 0.52, dist, LimitConfig(), geo.distance_excluding(own), body_depth=0.55)
    assert lim.limit_source == "cavity" and lim.upper == pytest.approx(0.5)


def test_sweep_points_keep_the_extremes() -> None:
    """A dense door with a handle: 600 sweep points always include the handle's tip and the free edge's corners."""
    door = _grid((0.0, 0.6), 0.0, (0.0, 0.8), nx=121, nz=161)
    tip = np.array([[0.55, -0.04, 0.4]])
    pts = sweep_points(np.concatenate([door, tip]), 600, np.random.default_rng(0))
    assert len(pts) == 600
    for corner in ([0.55, -0.04, 0.4], [0.6, 0.0, 0.0], [0.6, 0.0, 0.8]):
        assert np.any(np.all(np.isclose(pts, corner), axis=1)), corner


def test_the_sweep_moves_the_handle_but_not_the_floor_at_the_outline() -> None:
    """A door slab (x in [0, 0.6], z in [0, 0.8], front face y = -0.02) with a bar handle in front of it, standing
    on a floor: the attached faces hold both the handle and floor triangles just in front of the door's bottom
    edge; what sweeps with the door is the slab and the handle only."""
    from react3d_core.articulation.types import ArticulatedPart
    from react3d_core.assembly.scene import attached_faces, moving_faces
    from react3d_core.data.parts import OBB

    m = MeshBuilder(edge=0.05)
    m.add_box([0.0, -0.02, 0.0], [0.6, 0.0, 0.8], (150, 90, 60), key="door")
    m.add_box([0.5, -0.05, 0.3], [0.52, -0.02, 0.5], GREY, key="handle")
    m.add_box([-1.0, -1.0, -0.02], [2.0, 1.0, 0.0], GREY, key="floor")
    mesh, keys, ids = m.build()
    door, handle, floor = (np.flatnonzero(keys == ids[k]) for k in ("door", "handle", "floor"))
    pf = PartFrame(center=np.array([0.3, -0.01, 0.4]), u=np.array([0.0, 0.0, 1.0]), v=np.array([1.0, 0.0, 0.0]),
                   n=np.array([0.0, 1.0, 0.0]), su=0.8, sv=0.6, thickness=0.02)
    p = ArticulatedPart(candidate_id=0, label="openable", score=1.0, face_ids=door,
                        vertex_ids=np.unique(mesh.faces[door]), initial=Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0, 0, 0)),
                        articulation=Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0, 0, 0)),
                        obb=OBB(center=(0.3, -0.01, 0.4), axes=((0, 0, 1.0), (1.0, 0, 0), (0, 1.0, 0)), extents=(0.8, 0.6, 0.02)),
                        front_normal=pf.n, thickness=0.02, flat=True)
    own = attached_faces(mesh, p, pf)
    assert own[handle].all() and own[floor].any()  # floor triangles in front of the bottom edge are attached
    moving = moving_faces(mesh, own, p, pf)
    assert moving[door].all() and moving[handle].all() and not moving[floor].any()
