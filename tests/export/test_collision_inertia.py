"""Convex pieces and inertials: hand-computed boxes, parallel-axis sums, minimum mass, decomposition rules."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from react3d_core.data import TriMesh
from react3d_core.export.collision import convex_piece, convex_pieces, planar_patches
from react3d_core.config.export import ExportConfig
from react3d_core.export.inertia import Inertial, combine, inertial_from_pieces, principal
from react3d_core.export.model import joint_damping_for


def tm(m: trimesh.Trimesh) -> TriMesh:
    return TriMesh(m.vertices, m.faces)


def test_box_inertial_hand_computed() -> None:
    box = trimesh.creation.box(extents=[1, 2, 3]).apply_translation([1, 0, 0])
    inn = inertial_from_pieces(convex_pieces(tm(box)), density=1000, min_mass=0.1)
    assert inn.mass == pytest.approx(6000)
    np.testing.assert_allclose(inn.com, [1, 0, 0], atol=1e-12)
    # I = m/12 (b^2 + c^2): x 6000/12*13 = 6500, y 6000/12*10 = 5000, z 6000/12*5 = 2500
    np.testing.assert_allclose(np.diag(inn.tensor()), [6500, 5000, 2500], atol=1e-6)
    np.testing.assert_allclose(sorted(inn.moments), [2500, 5000, 6500])
    assert np.linalg.det(inn.axes) == pytest.approx(1)


def test_parallel_axis_combination_hand_computed() -> None:
    # two point-like 1 kg masses at x = +-1: COM 0, I_yy = I_zz = 2 * 1 * 1^2 = 2, I_xx = 0
    m, c, I = combine(np.array([1.0, 1.0]), np.array([[1.0, 0, 0], [-1.0, 0, 0]]), np.zeros((2, 3, 3)))
    assert m == 2 and np.allclose(c, 0)
    np.testing.assert_allclose(I, np.diag([0, 2, 2]))


def test_principal_moments_obey_triangle_inequality_and_floor() -> None:
    w, V = principal(np.diag([0.0, 2.0, 2.0]))
    assert np.all(w >= 1e-9)
    for i in range(3):
        assert w[i] <= w[(i + 1) % 3] + w[(i + 2) % 3] + 1e-12
    w, _ = principal(np.diag([5.0, 1.0, 1.0]))  # unphysical: clamped to 1 + 1
    assert max(w) == pytest.approx(2.0)


def test_light_bodies_get_min_mass_with_scaled_inertia() -> None:
    box = trimesh.creation.box(extents=[0.1, 0.1, 0.1])  # 1e-3 m^3 * 10 kg/m^3 = 0.01 kg
    inn = inertial_from_pieces(convex_pieces(tm(box)), density=10, min_mass=0.5)
    assert inn.mass == pytest.approx(0.5)
    np.testing.assert_allclose(inn.moments, 0.5 / 12 * (0.01 + 0.01))


def test_box_walls_are_kept_as_exact_pieces() -> None:
    walls = [trimesh.creation.box([0.5, 0.02, 0.3]).apply_translation([0, y, 0]) for y in (-0.24, 0.24)]
    pieces = convex_pieces(tm(trimesh.util.concatenate(walls)))
    assert [p.source for p in pieces] == ["component", "component"]
    assert sum(p.volume for p in pieces) == pytest.approx(2 * 0.5 * 0.02 * 0.3)


def test_flat_scan_becomes_a_box_of_min_thickness() -> None:
    sheet = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], [[0, 1, 2], [0, 2, 3]])
    piece = convex_piece(np.asarray(sheet.vertices), 0.01, "hull")
    assert piece.source == "box"
    assert piece.volume == pytest.approx(1 * 1 * 0.01)


def test_concave_watertight_part_is_decomposed() -> None:
    ring = trimesh.creation.annulus(r_min=0.1, r_max=0.2, height=0.1)
    pieces = convex_pieces(tm(ring), max_pieces=8)
    assert 2 <= len(pieces) <= 8 and all(p.source == "coacd" for p in pieces)
    # together close to the ring's volume, far below its hull's (a solid disc)
    total = sum(p.volume for p in pieces)
    assert total < 0.85 * ring.convex_hull.volume
    assert total == pytest.approx(ring.volume, rel=0.3)


def test_many_fragments_respect_the_piece_budget() -> None:
    cubes = [trimesh.creation.box([0.05] * 3).apply_translation([i * 0.1, 0, 0]) for i in range(10)]
    pieces = convex_pieces(tm(trimesh.util.concatenate(cubes)), max_pieces=4)
    assert len(pieces) == 4


def test_planar_patches_split_floor_and_wall() -> None:
    floor = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    wall = trimesh.Trimesh([[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]], [[0, 2, 1], [0, 3, 2]])
    patches = planar_patches(tm(trimesh.util.concatenate([floor, wall])), cell=2.0, min_thickness=0.01)
    assert len(patches) == 2  # one slab each, never the solid corner wedge
    assert all(p.volume == pytest.approx(0.01) for p in patches)


def test_about_joint_is_mass_or_moment_about_the_hinge_line():
    # a 2 kg body, COM 0.3 m from a vertical hinge line, moment 0.05 about the vertical through its COM
    inn = Inertial(2.0, np.array([1.3, 0.0, 0.5]), np.array([0.05, 0.2, 0.3]), np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]))
    assert inn.about_joint("prismatic", np.array([1.0, 0, 0]), np.zeros(3)) == 2.0
    # the principal axis of moment 0.05 is world -z, so the moment about z is 0.05; plus m d^2 = 2 * 0.3^2
    assert inn.about_joint("revolute", np.array([0, 0, -1.0]), np.array([1.0, 0.0, 7.0])) == pytest.approx(0.05 + 0.18)


def test_joint_damping_is_capped_by_what_the_joint_moves():
    cfg = ExportConfig(joint_damping=1.0, joint_damping_max_rate=10.0)
    assert joint_damping_for(0.4, cfg) == 1.0  # a door: 10 * 0.4 = 4 > 1
    assert joint_damping_for(1e-4, cfg) == pytest.approx(1e-3)  # a 0.1 kg sliver near its hinge
    assert joint_damping_for(2.0, ExportConfig(joint_damping=0.0)) == 0.0


def test_a_body_whose_colliders_were_all_cut_away_gets_its_inertial_from_what_it_shows() -> None:
    """A carcass lying inside another loses every piece to the clearance; the export must still
    complete. 0.4 x 0.5 x 0.6 m box at (1, 2, 3): volume 0.12 m^3, centre of mass at its centre."""
    import trimesh

    from react3d_core.config.export import ExportConfig
    from react3d_core.data.mesh import TriMesh
    from react3d_core.export.model import _body_inertial

    box = trimesh.creation.box(extents=(0.4, 0.5, 0.6)).apply_translation((1.0, 2.0, 3.0))
    cfg = ExportConfig()
    stats: dict = {}
    inertial = _body_inertial([], [TriMesh(box.vertices, box.faces)], cfg, stats)
    assert stats == {"bodies_without_colliders": 1}
    assert inertial.mass == pytest.approx(max(0.12 * cfg.density_kg_m3, cfg.min_mass_kg))
    assert np.allclose(inertial.com, (1.0, 2.0, 3.0))
    flat = TriMesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float), np.array([[0, 1, 2]]))
    point = _body_inertial([], [flat], cfg, stats)  # no volume: a point mass at what it shows
    assert stats["bodies_without_colliders"] == 2 and point.mass == cfg.min_mass_kg
    assert np.allclose(point.com, (1 / 3, 1 / 3, 0))


def test_rpy_at_gimbal_lock_gives_the_rotation_without_a_warning() -> None:
    import warnings

    from scipy.spatial.transform import Rotation

    from react3d_core.export.inertia import rpy_of

    R = Rotation.from_euler("xyz", [0.3, np.pi / 2, 0.7]).as_matrix()  # a box standing on end: pitch 90 deg
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rpy = rpy_of(R)
    assert rpy[1] == pytest.approx(np.pi / 2) and rpy[2] == 0.0  # roll and yaw share one axis: yaw set to 0
    assert np.allclose(Rotation.from_euler("xyz", rpy).as_matrix(), R, atol=1e-12)
