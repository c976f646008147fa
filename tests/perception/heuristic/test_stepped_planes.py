"""A small front standing a few centimetres behind a large one of the same direction (a microwave on its
cabinet, set back from the cabinet's doors) peaks in the offset vote within the large front's peak
separation: the faces no peak took vote again, and a peak of theirs is a plane when the offsets of all the
direction's faces dip between it and the large front. A bent wall's offsets form a plateau with no dip."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import PlanesConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.planes import Plane, vertical_planes

from tests.perception.heuristic.test_free_standing_planes import _sheet

CAM = np.array([0.5, -2.0, 1.2])
ON = PlanesConfig(residual_dip=0.75)  # the second vote is opt-in


def _mesh(parts: list[tuple[np.ndarray, np.ndarray]]) -> TriMesh:
    off = np.cumsum([0] + [len(p[0]) for p in parts[:-1]])
    verts = np.concatenate([p[0] for p in parts])
    faces = np.concatenate([p[1] + o for p, o in zip(parts, off)])
    return TriMesh(verts, faces, np.full((len(verts), 3), 150, np.uint8))


def _cabinet_and_microwave(setback: float) -> TriMesh:
    """A 0.8 x 0.8 m cabinet front at y = 0 and a 0.44 x 0.26 m microwave front ``setback`` behind it standing
    on the cabinet (z 0.82-1.08), both facing -y with 1.5 mm of scan noise, and a wall 0.6 m behind."""
    rng = np.random.default_rng(3)
    v, f = _sheet(0.8, 0.8, 0.02, 0.0015, rng)
    cab = (v, f)
    v, f = _sheet(0.44, 0.26, 0.02, 0.0015, rng)
    mw = (v + [0.1, setback, 0.82], f)
    v, f = _sheet(3.0, 2.5, 0.02, 0.0015, rng)
    wall = (v + [-1.0, 0.6, 0.0], f)
    return _mesh([cab, mw, wall])


def _microwave_planes(planes: list[Plane]) -> list[Plane]:
    """Planes whose middle lies on the microwave's front (its height, not the wall's depth)."""
    mids = [p.to_world(np.mean(p.extent_u), np.mean(p.extent_v)) for p in planes]
    return [p for p, m in zip(planes, mids) if 0.85 < m[2] < 1.06 and m[1] < 0.3]


def test_the_set_back_front_is_a_plane_of_its_own() -> None:
    mesh = _cabinet_and_microwave(0.03)
    found = _microwave_planes(vertical_planes(mesh, CAM, ON, max_tilt=0.25))
    assert len(found) == 1
    p = found[0]
    assert abs(p.n @ [0.0, 1.0, 0.0]) > 0.999
    assert abs(abs(p.d) - 0.03) < 0.005
    assert abs(p.area - 0.44 * 0.26) < 0.01
    assert abs((p.extent_v[1] - p.extent_v[0]) - 0.26) < 0.02


def test_one_vote_loses_it_within_the_peak_separation() -> None:
    """The case the second vote is for: 3 cm is inside the 5 cm separation of offset peaks."""
    mesh = _cabinet_and_microwave(0.03)
    one = vertical_planes(mesh, CAM, PlanesConfig(), max_tilt=0.25)
    assert not _microwave_planes(one)
    # the cabinet's plane still holds its own faces only: the microwave's lie beyond the offset tolerance
    cab = [p for p in one if abs(p.d) < 0.01 and p.extent_v[1] < 0.85]
    assert len(cab) == 1 and abs(cab[0].area - 0.64) < 0.03


def test_a_bent_wall_gives_no_second_plane() -> None:
    """A wall bowing 6 cm towards its ends (no straighter direction to refit it on): its offsets fall away
    from the middle's peak with no dip, so the ends the first peak left give no plane. Taken without the
    dip, each end would be a plane 3-6 cm in front of the wall."""
    rng = np.random.default_rng(5)
    v, f = _sheet(3.0, 2.5, 0.02, 0.0015, rng)
    v[:, 1] += 0.06 * ((v[:, 0] - 1.5) / 1.5) ** 2
    mesh = _mesh([(v, f)])
    with_ = vertical_planes(mesh, CAM, ON, max_tilt=0.25)
    without = vertical_planes(mesh, CAM, PlanesConfig(), max_tilt=0.25)
    assert len(with_) == 1
    assert [round(p.area, 6) for p in with_] == [round(p.area, 6) for p in without]


def test_a_doubled_surface_on_a_front_is_its_relief() -> None:
    """A 0.4 x 0.4 m sheet 3 cm behind the middle of a 0.8 x 0.8 m front (a TSDF scan's doubled surface, a
    recessed panel) lies on the front's footprint: it is the front's relief, not a front of its own. With the
    footprint test off (any share allowed) it would be a plane."""
    rng = np.random.default_rng(7)
    v, f = _sheet(0.8, 0.8, 0.02, 0.0015, rng)
    front = (v, f)
    v, f = _sheet(0.4, 0.4, 0.02, 0.0015, rng)
    panel = (v + [0.2, 0.03, 0.2], f)
    mesh = _mesh([front, panel])
    def middle(planes: list[Plane]) -> list[Plane]:
        return [p for p in planes if abs(abs(p.d) - 0.03) < 0.01]
    assert not middle(vertical_planes(mesh, CAM, ON, max_tilt=0.25))
    loose = ON.model_copy(update={"residual_max_stack": 1.0})
    assert len(middle(vertical_planes(mesh, CAM, loose, max_tilt=0.25))) == 1


def test_layer_share_by_hand() -> None:
    """A 0.16 x 0.16 m piece on a 4 cm grid occupies 4 x 4 cells; other faces covering its left half hold 8 of
    them: share 0.5. Faces elsewhere hold none."""
    verts = np.array([[0.005, 0, 0.005], [0.155, 0, 0.005], [0.155, 0, 0.155], [0.005, 0, 0.155],   # the piece
                      [0.005, 0.03, 0.005], [0.075, 0.03, 0.005], [0.075, 0.03, 0.155], [0.005, 0.03, 0.155],  # left half
                      [1.005, 0.03, 0.005], [1.075, 0.03, 0.005], [1.075, 0.03, 0.155]], float)  # far away
    faces = np.array([[0, 2, 1], [0, 3, 2], [4, 6, 5], [4, 7, 6], [8, 10, 9]])
    mesh = TriMesh(verts, faces, np.full((len(verts), 3), 150, np.uint8))
    from react3d_core.perception.heuristic.planes import _Samples, layer_share, surface_samples
    pts, face, w = surface_samples(mesh.vertices[mesh.faces], mesh.face_areas, 0.02)
    samples = _Samples(pts, face, w, np.zeros(mesh.n_faces, bool))
    piece = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.array([0, 1]), (0.0, 0.16), (0.0, 0.16), 0.0225)
    assert layer_share(piece, np.array([2, 3]), samples, 0.04) == 0.5
    assert layer_share(piece, np.array([4]), samples, 0.04) == 0.0
    assert layer_share(piece, np.array([], int), samples, 0.04) == 0.0
