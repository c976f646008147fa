"""Units of export/clearance.py and the slab patches, on shapes whose answers are computed by hand."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from react3d_core.data import Articulation, TriMesh
from react3d_core.export.clearance import (
    carve_faces,
    cavity_obstacle,
    clip_halfspace,
    face_conflicts,
    gap,
    hull_obstacle,
    keep_side,
    keep_clear,
    piece_axes,
    separate_at_rest,
    sweep_obstacles,
    territory_plane,
)
from react3d_core.export.collision import ConvexPiece, planar_patches


def cube(lo, hi) -> ConvexPiece:  # noqa: ANN001
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    b = trimesh.creation.box(extents=hi_ - lo_).apply_translation((lo_ + hi_) / 2)
    return ConvexPiece(np.asarray(b.vertices), np.asarray(b.faces), "box")


def volume(points: np.ndarray) -> float:
    return float(trimesh.Trimesh(points, process=False).convex_hull.volume)


def test_gap_is_the_separation_along_the_best_axis() -> None:
    a = cube((0, 0, 0), (1, 1, 1))
    ob = hull_obstacle(cube((1.01, 0.2, 0.2), (2, 0.8, 0.8)).vertices, "b", "rest")
    g, axis, side = gap(a.vertices, piece_axes(a), ob)
    assert g == pytest.approx(0.01)
    assert abs(axis[0]) == pytest.approx(1.0)
    ob = hull_obstacle(cube((0.98, 0.2, 0.2), (2, 0.8, 0.8)).vertices, "b", "rest")
    assert gap(a.vertices, piece_axes(a), ob)[0] == pytest.approx(-0.02)  # overlap: least penetration


def test_clip_halfspace_is_exact() -> None:
    pts = clip_halfspace(cube((0, 0, 0), (1, 1, 1)).vertices, np.array([1.0, 0, 0]), 0.25)
    assert volume(pts) == pytest.approx(0.25)
    # an oblique cut of the unit cube through x + y <= 1: half of it
    pts = clip_halfspace(cube((0, 0, 0), (1, 1, 1)).vertices, np.array([1.0, 1.0, 0]) / np.sqrt(2), 1 / np.sqrt(2))
    assert volume(pts) == pytest.approx(0.5)
    assert clip_halfspace(cube((0, 0, 0), (1, 1, 1)).vertices, np.array([1.0, 0, 0]), -0.1) is None


def test_keep_clear_makes_the_cut_that_keeps_most() -> None:
    slab = cube((0, 0, 0), (1, 1, 0.01))
    ob = hull_obstacle(cube((0.8, 0.2, -0.1), (1.2, 0.4, 0.1)).vertices, "o", "rest")
    out, st = keep_clear([slab], [ob], 0.005)
    # candidate cuts keep x <= 0.795 (0.795), y >= 0.405 (0.595) or y <= 0.195 (0.195) of the slab
    assert st.cut == 1 and len(out) == 1
    assert out[0].volume == pytest.approx(0.795 * 0.01, rel=1e-6)
    assert gap(out[0].vertices, piece_axes(out[0]), ob)[0] >= 0.005 - 1e-9


def test_prismatic_sweep_is_the_hull_of_both_ends() -> None:
    p = cube((0, 0, 0), (0.1, 0.1, 0.1))
    art = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0, 0, 0), lower=0.0, upper=0.4)
    (ob,) = sweep_obstacles([p], art, "d", 0.005)
    assert volume(ob.vertices) == pytest.approx(0.1 * 0.5 * 0.1)
    assert ob.lo[1] == pytest.approx(-0.4) and ob.hi[1] == pytest.approx(0.1)


def test_revolute_sweep_covers_the_arc_within_its_growth() -> None:
    door = cube((0, 0, 0), (0.6, 0.02, 0.7))  # hinge along z at the origin, swinging out to -y
    art = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0, 0, 0), lower=0.0, upper=np.pi / 2)
    margin = 0.005
    obs = sweep_obstacles([door], art, "d", margin)
    r = np.hypot(0.6, 0.02)
    assert all(ob.grow <= margin / 2 + 1e-12 for ob in obs)
    assert len(obs) == int(np.ceil((np.pi / 2) / (2 * np.arccos(1 - margin / 2 / r))))
    qs = np.linspace(0, np.pi / 2, 181)
    pts = np.vstack([art.move(door.vertices, q) for q in qs])
    for p in pts:  # every point of the moving door lies in some obstacle grown by its chord error
        inside = [np.all(ob.normals @ p <= ob.vmax + ob.grow + 1e-9) for ob in obs]
        assert any(inside)


def test_overlapping_parts_at_rest_the_smaller_piece_yields() -> None:
    big = cube((0, 0, 0), (1, 0.02, 0.6))
    small = cube((0.95, 0, 0.2), (1.1, 0.02, 0.3))
    (a, b), st = separate_at_rest([[big], [small]], 0.005)
    assert a[0] is big and st.cut == 1
    assert b[0].vertices[:, 0].min() >= 1.005 - 1e-9  # cut off where it lay on the big one
    assert b[0].volume == pytest.approx(0.095 * 0.02 * 0.1)


def test_face_conflicts_and_carving_split_big_faces() -> None:
    # a 4 m wall of two triangles and a 0.5 m box 2 mm in front of its middle
    wall = trimesh.Trimesh([[-2, 0, 0], [2, 0, 0], [2, 0, 2], [-2, 0, 2]], [[0, 1, 2], [0, 2, 3]], process=False)
    ob = hull_obstacle(cube((-0.25, -0.5, 0.5), (0.25, -0.002, 1.0)).vertices, "c", "carcass")
    conflict = face_conflicts(wall.vertices, wall.faces, [ob], 0.005)
    assert conflict.all()  # both big triangles come within 5 mm
    keep, frags = carve_faces(wall.vertices, wall.faces, [ob], 0.005, min_edge=0.1)
    assert not keep.any()
    kept = trimesh.Trimesh(frags.reshape(-1, 3), np.arange(frags.size // 3).reshape(-1, 3), process=False).area
    assert 8.0 - 0.25 >= kept >= 8.0 - 1.0  # the wall less at least the box's shadow (0.25 m2), at most 1 m2 with the split's rounding
    again = face_conflicts(frags.reshape(-1, 3), np.arange(frags.size // 3).reshape(-1, 3), [ob], 0.005)
    assert not again.any()
    far = hull_obstacle(cube((-0.25, -0.5, 0.5), (0.25, -0.1, 1.0)).vertices, "c", "carcass")
    assert not face_conflicts(wall.vertices, wall.faces, [far], 0.005).any()


def tm(mesh: trimesh.Trimesh) -> TriMesh:
    return TriMesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), np.zeros((len(mesh.vertices), 3), np.uint8))


def test_patches_lie_behind_their_surface() -> None:
    floor = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    (p,) = planar_patches(tm(floor), cell=2.0, min_thickness=0.01)
    assert p.vertices[:, 2].max() == pytest.approx(0.0)  # the slab's top is the floor
    assert p.vertices[:, 2].min() == pytest.approx(-0.01)
    (p,) = planar_patches(tm(floor), cell=2.0, min_thickness=0.01, slab=0.02)
    assert p.vertices[:, 2].max() == pytest.approx(0.0) and p.vertices[:, 2].min() == pytest.approx(-0.02)


def test_patches_split_parallel_surfaces_and_keep_clear_of_obstacles() -> None:
    # two parallel -y facing surfaces 0.3 m apart in one 0.5 m cell: one slab would fill the space between
    a = trimesh.Trimesh([[0, 0, 0], [0, 0, 0.4], [0.4, 0, 0.4], [0.4, 0, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    b = a.copy().apply_translation((0, 0.3, 0))
    mesh = tm(trimesh.util.concatenate([a, b]))
    assert len(planar_patches(mesh, cell=0.5, min_thickness=0.005)) == 1
    split = planar_patches(mesh, cell=0.5, min_thickness=0.005, min_cell=0.05, flatness=0.02)
    assert len(split) >= 2 and all(np.ptp(p.vertices[:, 1]) <= 0.02 for p in split)
    ob = hull_obstacle(cube((0.1, -0.2, 0.1), (0.3, -0.001, 0.3)).vertices, "d", "sweep")
    clear = planar_patches(mesh, cell=0.5, min_thickness=0.005, min_cell=0.05, flatness=0.02, obstacles=[ob], margin=0.005)
    assert all(gap(p.vertices, piece_axes(p), ob)[0] >= 0.005 - 1e-9 for p in clear)
    assert sum(p.volume for p in clear) >= 0.5 * sum(p.volume for p in split)  # the rest of the surfaces still collides


def test_territory_plane_bisects_turned_fronts_and_splits_coplanar_ones() -> None:
    def front(cx: float, t: float) -> tuple[np.ndarray, np.ndarray]:
        u, n = np.array([np.cos(t), np.sin(t), 0]), np.array([-np.sin(t), np.cos(t), 0])
        s = np.linspace(-0.25, 0.25, 11)
        return np.array([cx, 0.5, 0.5]) + s[:, None] * u, n

    t = np.radians(6)
    (fa, na), (fb, nb) = front(-0.2515, -t), front(0.2515, t)
    m, c = territory_plane(fa, na, fb, nb)
    assert abs(m[0]) == pytest.approx(1.0) and c * np.sign(m[0]) == pytest.approx(0.0, abs=1e-9)  # the plane x = 0
    # stacked, nearly parallel fronts (yaw noise): the bisector would cut both in half; the gap is used instead
    fa = np.array([[x, 0.5, z] for x in np.linspace(-0.25, 0.25, 5) for z in (0.3, 0.5)])
    fb = fa + np.array([0, 0, 0.203])
    m, c = territory_plane(fa, np.array([np.sin(0.05), np.cos(0.05), 0]), fb, np.array([-np.sin(0.05), np.cos(0.05), 0]))
    assert m @ np.array([0, 0, 1.0]) == pytest.approx(1.0) and c == pytest.approx(0.5015)  # between z = 0.5 and 0.503


def box_piece(lo, hi) -> ConvexPiece:  # noqa: ANN001
    """An axis-aligned box piece that knows it is a box (written as a box primitive)."""
    c = cube(lo, hi)
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    return ConvexPiece(c.vertices, c.faces, "patch", np.concatenate([(lo_ + hi_) / 2, np.eye(3).reshape(9), hi_ - lo_]))


def test_cavity_is_the_walls_hull_moved_in_by_their_thickness() -> None:
    # five 0.02 m walls of a cabinet [0, 0.5] x [0, 0.4] x [0, 0.6], open at y = 0 (the front)
    t = 0.02
    walls = [box_piece((0, 0, 0), (t, 0.4, 0.6)), box_piece((0.5 - t, 0, 0), (0.5, 0.4, 0.6)),
             box_piece((t, 0, 0), (0.5 - t, 0.4, t)), box_piece((t, 0, 0.6 - t), (0.5 - t, 0.4, 0.6)),
             box_piece((t, 0.4 - t, t), (0.5 - t, 0.4, 0.6 - t))]
    cav = cavity_obstacle(walls, "cab")
    assert cav is not None and cav.kind == "cavity"
    np.testing.assert_allclose(cav.lo, [t, t, t], atol=1e-9)  # the open front is moved in too
    np.testing.assert_allclose(cav.hi, [0.5 - t, 0.4 - t, 0.6 - t], atol=1e-9)
    inside = cube((0.2, 0.1, 0.2), (0.3, 0.2, 0.3))
    assert gap(inside.vertices, piece_axes(inside), cav)[0] < 0
    outside = cube((0.6, 0.1, 0.2), (0.7, 0.2, 0.3))  # beside the cabinet: 0.6 - 0.48 from the cavity
    assert gap(outside.vertices, piece_axes(outside), cav)[0] == pytest.approx(0.12)
    assert cavity_obstacle([box_piece((0, 0, 0), (0.03, 0.03, 0.03))], "solid") is None  # no room inside
    assert cavity_obstacle([], "none") is None


def test_a_box_cut_along_its_own_axis_stays_a_box() -> None:
    slab = box_piece((0, 0, -0.02), (1, 1, 0))
    ob = hull_obstacle(cube((0.8, -0.5, -0.5), (1.5, 1.5, 0.5)).vertices, "o", "sweep")
    (out,), st = keep_clear([slab], [ob], 0.005)
    assert st.cut == 1 and out.box is not None  # still a box primitive
    c, R, ext = out.box_frame()
    np.testing.assert_allclose(ext, [0.795, 1, 0.02], atol=1e-9)
    np.testing.assert_allclose(c, [0.3975, 0.5, -0.01], atol=1e-9)
    # an oblique obstacle face: the cut is not along a box axis, the piece becomes a general hull
    tilted = trimesh.creation.box(extents=(0.4, 3, 1)).apply_transform(trimesh.transformations.rotation_matrix(np.radians(30), (0, 0, 1)))
    ob = hull_obstacle(np.asarray(tilted.vertices) + [1.0, 0.5, 0], "o", "sweep")
    (out,), _ = keep_clear([slab], [ob], 0.005)
    assert out.box is None and gap(out.vertices, piece_axes(out), ob)[0] >= 0.005 - 1e-9


def test_territory_plane_of_side_by_side_fronts_with_one_normal_flipped_lies_across_the_row() -> None:
    # two doors side by side in the plane y = 0.5 (x in [0, 0.5] and [0.5015, 1], z in [0, 0.8]), the door
    # fronts' own vertices a few mm deep (front and back face); the second door's normal estimated flipped.
    # The bisector of the two normals is a plane y = const through both fronts (it cut a door's colliders
    # away); the plane must be x = 0.50075, across the row
    a = np.array([[x, y, z] for x in (0.0, 0.5) for y in (0.5, 0.502, 0.503) for z in (0.0, 0.8)])
    b = a + np.array([0.5015, -0.004, 0.0])
    for tilt in (0.0, 5.0):  # exactly opposite, or 5 degrees further off
        t = np.radians(tilt)
        m, c = territory_plane(a, np.array([0, 1.0, 0]), b, np.array([np.sin(t), -np.cos(t), 0]), axes=np.eye(3))
        assert m[0] > np.cos(np.radians(3.0))  # across the row (2.5 degrees off x with the 5-degree tilt)
        assert (a @ m).max() <= c <= (b @ m).min()
        if tilt == 0.0:
            np.testing.assert_allclose(m, [1, 0, 0], atol=1e-12)
            assert c == pytest.approx(0.50075)
    # back to back (carcasses meeting behind them): the bisector, y = 0.3, between them
    back = np.array([[x, 0.6, z] for x in (0.0, 0.5) for z in (0.0, 0.8)])
    m, c = territory_plane(a[a[:, 1] == 0.5] - [0, 0.5, 0], np.array([0, 1.0, 0]), back, np.array([0, -1.0, 0]), axes=np.eye(3))
    np.testing.assert_allclose(m, [0, 1, 0], atol=1e-12)
    assert c == pytest.approx(0.3)


def test_territory_plane_lies_across_the_axis_that_separates_the_fronts() -> None:
    # a tall door (x in [0, 0.5], z in [0, 0.8]) beside a short drawer high up (x in [0.5015, 1], z in [0.6, 0.8]):
    # the line between their centres is 32 degrees off the row; the plane must be x = 0.50075
    door = np.array([[x, 0.5, z] for x in (0.0, 0.5) for z in (0.0, 0.8)])
    drawer = np.array([[x, 0.5, z] for x in (0.5015, 1.0) for z in (0.6, 0.8)])
    n = np.array([0, 1.0, 0])
    m, c = territory_plane(door, n, drawer, n)
    assert abs(m[2]) > 0.3  # without axes: tilted along the centres' line
    m, c = territory_plane(door, n, drawer, n, axes=np.eye(3))
    np.testing.assert_allclose(m, [1, 0, 0], atol=1e-12)
    assert c == pytest.approx(0.50075)
    # stacked: across z, in the middle of the (negative) gap where the fronts overlap by 2 cm
    upper = np.array([[x, 0.5, z] for x in (0.0, 0.5) for z in (0.58, 0.8)])
    lower = np.array([[x + 0.02, 0.5, z] for x in (0.0, 0.5) for z in (0.3, 0.6)])
    m, c = territory_plane(upper, n, lower, n, axes=np.eye(3))
    np.testing.assert_allclose(m, [0, 0, -1], atol=1e-12)
    assert c == pytest.approx(-0.59)


def test_keep_side_leaves_a_piece_that_would_lose_too_much() -> None:
    bottom = cube((0, 0, 0.315), (0.5, 0.5, 0.32))  # a drawer's bottom just under the plane z = 0.321
    m, c = np.array([0, 0, -1.0]), -0.321  # keep z >= 0.321
    assert keep_side([bottom], m, c) == ([], 1)  # dropped
    (kept,), n = keep_side([bottom], m, c, max_loss=0.3)
    assert kept is bottom and n == 0
    wall = cube((0, 0, 0.3), (0.5, 0.005, 0.5))  # loses 0.021 / 0.2 = 10.5 %: cut
    (cut,), n = keep_side([wall], m, c, max_loss=0.3)
    assert n == 1 and cut.vertices[:, 2].min() == pytest.approx(0.321)


def test_interleaved_carcass_walls_are_moved_to_their_side_not_dropped():
    from react3d_core.export.model import shift_walls

    # a cupboard above a drawer; its carcass keeps z >= 0.48 (m = -z, c = -0.48). Its floor was estimated
    # at z 0.45..0.475, wholly below: moved up by 0.48 - 0.45 = 0.03 to z 0.48..0.505, so its cavity stays closed
    m, c = np.array([0.0, 0.0, -1.0]), -0.48
    floor = cube([0.0, 0.0, 0.45], [0.4, 0.5, 0.475])
    far = cube([0.0, 0.0, 0.30], [0.4, 0.5, 0.32])  # 16 cm past: not a wall of this carcass's boundary
    side = cube([0.0, 0.0, 0.45], [0.02, 0.5, 1.2])  # crossed by the plane: left to the cut
    out = shift_walls([floor, far, side], m, c)
    np.testing.assert_allclose(out[0].vertices.min(0), [0.0, 0.0, 0.48], atol=1e-12)
    np.testing.assert_allclose(out[0].vertices.max(0), [0.4, 0.5, 0.505], atol=1e-12)
    assert out[1] is far and out[2] is side
    kept, _ = keep_side(out, m, c)
    assert len(kept) == 2  # the moved floor and the cut side; the far plate is dropped


def test_a_wall_at_an_angle_to_the_plane_is_not_moved_by_its_depth():
    from react3d_core.export.model import shift_walls

    # a cupboard's roof 0.74 m deep (x), z 0.346..0.355, under a plane tilted 8 degrees (the bisector with a
    # drawer front estimated 16 degrees off level): the roof lies wholly past it, but 10 cm deep along m.
    # Moved until its far face met the plane it would sit 12 cm down, in the middle of its own cavity.
    t = np.radians(8.0)
    m = np.array([-np.sin(t), 0.0, -np.cos(t)])  # the cupboard keeps m . x <= c (below the plane)
    roof = cube([4.081, 4.05, 0.346], [4.825, 4.38, 0.355])
    c = float((roof.vertices @ m).min()) - 0.005  # its nearest corner 5 mm past the plane
    (out,) = shift_walls([roof], m, c)
    assert out is roof
    thin = cube([4.081, 4.05, 0.346], [4.125, 4.38, 0.355])  # a wall thin along m is still moved onto the plane
    c = float((thin.vertices @ m).min()) - 0.005
    (moved,) = shift_walls([thin], m, c)
    assert float((moved.vertices @ m).max()) == pytest.approx(c)


def test_fronts_apart_only_when_the_plane_parts_them():
    from react3d_core.export.model import fronts_apart

    # stacked fronts, plane at 0.48: a drawer below, a 1.66 m door above reaching 3.1 cm below it (1.9 %): apart
    assert fronts_apart(np.array([0.052, 0.478]), np.array([0.449, 2.107]), 0.48)
    # a 0.117 m fragment with half of its width past the plane (a duplicate of its neighbour): not apart
    assert not fronts_apart(np.array([2.644, 2.761]), np.array([2.64, 3.14]), 2.70)
