"""On the room's outer walls only room doors stand (hand-built scenes)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import FloorConfig, FrontRulesConfig, HeuristicConfig, RoomWallConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.geometry import concat_meshes
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.room_walls import keep_room_doors, on_outer_wall


def _wall(x0: float, x1: float, y: float, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """A rectangle in the plane y = ``y`` facing -y (towards the room)."""
    v = np.array([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _floor(x0: float, x1: float, y0: float, y1: float) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _mesh(*quads: tuple[np.ndarray, np.ndarray]) -> TriMesh:
    return TriMesh(*concat_meshes(quads))


def _front(x0: float, x1: float, z0: float, z1: float, y: float, faces: list[int] | None = None) -> Front:
    return Front(facet=-1, handle_facets=[], center=np.array([(x0 + x1) / 2, y, (z0 + z1) / 2]),
                 n_out=np.array([0.0, -1.0, 0.0]), u=np.array([1.0, 0.0, 0.0]), extent_u=(x0, x1), extent_v=(z0, z1),
                 faces=np.array(faces or [], np.int64), kind="drop")


def test_wall_faces_towards_the_room() -> None:
    v, f = _wall(0, 1, 3.0, 0, 1)
    assert np.allclose(TriMesh(v, f).face_normals, [0.0, -1.0, 0.0])


def test_fronts_on_the_outer_wall_are_dropped_unless_shaped_like_a_room_door() -> None:
    """A room: floor (y -1..3), outer wall y = 3 (x -1..5, 2.5 m high), a base unit's front plane at
    y = 2.4 (its door faces are the quad at y 2.4). Fronts:
    - the base door, 0.6 m in front of the wall: the wall lies behind its plane (kept, not re-typed);
    - a 0.5 x 0.7 m "front" painted on the wall at 1.0-1.7 m: nothing behind, not door-shaped (dropped);
    - a 0.9 x 2.0 m front on the wall from the floor with a horizontal lever at its right: a room door,
      kept and re-typed from the shape rules' bottom-hinged guess to a door hinged at its left edge."""
    mesh = _mesh(_floor(-1, 5, -1, 3), _wall(-1, 5, 3.0, 0, 2.5), _wall(0, 0.6, 2.4, 0.1, 0.85))
    base = _front(0.0, 0.6, 0.1, 0.85, 2.4, faces=[4, 5])
    painted = _front(3.0, 3.5, 1.0, 1.7, 3.0)
    door = _front(3.8, 4.7, 0.0, 2.0, 3.0)
    door.handle_points = np.array([[4.45, 2.96, 1.0], [4.6, 2.96, 1.0], [4.6, 2.96, 1.02]])
    rules = RoomWallConfig()
    assert on_outer_wall([base, painted, door], mesh, rules) == [False, True, True]
    kept = keep_room_doors([base, painted, door], mesh, rules, FrontRulesConfig(), FloorConfig())
    assert kept == [base, door]
    assert base.kind == "drop"
    assert door.kind == "door"
    a = door.articulation
    assert a.joint_type == "revolute"
    assert abs(abs(a.axis[2]) - 1.0) < 1e-9
    assert np.allclose(a.origin[:2], [3.8, 3.0])


def test_behind_share_is_the_area_behind_over_the_whole_scan() -> None:
    """A 4 x 2.5 m wall (10 m²) and a patch 0.5 m behind it. Hand-computed share: a 0.2 x 0.2 m patch gives
    0.04 / 10.04 = 0.0040 < 0.005 (an outer wall: a few stray faces behind it do not matter); a 0.3 x 0.3 m
    patch gives 0.09 / 10.09 = 0.0089 >= 0.005 (not); the patch only 5 cm behind is within ``depth`` (an
    outer wall again)."""
    f = [_front(1.0, 1.5, 1.0, 1.6, 3.0)]
    rules = RoomWallConfig(behind_share=0.005, depth=0.1, min_area=1.0)
    small = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall(1, 1.2, 3.5, 1, 1.2))
    large = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall(1, 1.3, 3.5, 1, 1.3))
    near = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall(1, 1.3, 3.05, 1, 1.3))
    assert on_outer_wall(f, small, rules) == [True]
    assert on_outer_wall(f, large, rules) == [False]
    assert on_outer_wall(f, near, rules) == [True]


def test_a_radiator_hung_on_the_outer_wall_is_on_it() -> None:
    """A 0.8 x 0.6 m radiator 8 cm proud of a 4 x 2.5 m outer wall, cut into 0.2 m "fronts": its own plane
    holds only its 0.48 m² (under ``min_area``), but the wall 8 cm behind lies within ``wall_band`` and
    nothing lies farther behind: on the wall. With the band at 0 the radiator stands alone, and stays.
    A base unit's front 0.5 m before the wall is no such front (the wall lies farther behind it)."""
    mesh = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall(1.0, 1.8, 2.92, 0.15, 0.75), _wall(2.5, 3.1, 2.5, 0.1, 0.85))
    rads = [_front(1.0 + 0.2 * k, 1.2 + 0.2 * k, 0.15, 0.75, 2.92, faces=[2, 3] if k == 0 else []) for k in range(4)]
    base = _front(2.5, 3.1, 0.1, 0.85, 2.5, faces=[4, 5])
    assert on_outer_wall(rads + [base], mesh, RoomWallConfig()) == [True] * 4 + [False]
    assert on_outer_wall(rads + [base], mesh, RoomWallConfig(wall_band=0.0)) == [False] * 5
    assert keep_room_doors(rads + [base], mesh, RoomWallConfig(), FrontRulesConfig(), FloorConfig()) == [base]


def test_a_lone_cabinet_scanned_from_the_front_is_no_wall() -> None:
    """Only the cabinet's two doors were scanned (nothing behind their plane, but no wall around them
    either: every face in the plane belongs to a front): both kept as they were."""
    mesh = _mesh(_wall(0, 0.5, 1.0, 0.1, 0.8), _wall(0.5, 1.0, 1.0, 0.1, 0.8), _floor(-1, 2, -1, 0.9))
    fronts = [_front(0, 0.5, 0.1, 0.8, 1.0, faces=[0, 1]), _front(0.5, 1.0, 0.1, 0.8, 1.0, faces=[2, 3])]
    assert on_outer_wall(fronts, mesh, RoomWallConfig()) == [False, False]
    assert keep_room_doors(fronts, mesh, RoomWallConfig(), FrontRulesConfig(), FloorConfig()) == fronts


def test_rule_switches_off() -> None:
    assert HeuristicConfig(room_wall={"enabled": False}).room_wall.enabled is False
    r = HeuristicConfig().room_wall
    assert r.enabled and r.behind_share == 0.005 and r.door_w == (0.6, 1.3)


def _wall_back(x0: float, x1: float, y: float, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """A rectangle in the plane y = ``y`` facing +y (away from the room): a modelled wall's outer side."""
    v, f = _wall(x0, x1, y, z0, z1)
    return v, f[:, ::-1].copy()


def test_a_modelled_wall_s_own_outer_side_is_not_surface_behind_it() -> None:
    """A 4 x 2.5 m wall at y = 3 modelled with thickness: its outer side, 4 x 2.5 m at y = 3.12 facing
    +y, is half the mesh (10 / 20 m², share 0.5, far over behind_share 0.005), so a front painted on
    the wall was not on an outer wall and its cells and 'handles' (the wall's paint at a room corner)
    stayed fronts (tuning mixed rooms 13, 14: 6 false fronts each). No camera in the room sees that
    side: within wall_back (0.3 m) and facing away (normal . n_out = -1 < -0.9) it is left out. A face
    facing away 0.5 m behind (beyond wall_back), or one 0.12 m behind facing the room (a niche), still
    counts; wall_back 0 restores the old reading."""
    painted = [_front(1.0, 1.5, 1.0, 1.7, 3.0)]
    rules = RoomWallConfig()
    assert rules.wall_back == 0.3
    thick = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall_back(0, 4, 3.12, 0, 2.5))
    assert np.allclose(TriMesh(*concat_meshes([_wall_back(0, 4, 3.12, 0, 2.5)])).face_normals, [0.0, 1.0, 0.0])
    assert on_outer_wall(painted, thick, rules) == [True]
    assert on_outer_wall(painted, thick, RoomWallConfig(wall_back=0.0)) == [False]
    far = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall_back(0, 4, 3.5, 0, 2.5))
    assert on_outer_wall(painted, far, rules) == [False]
    niche = _mesh(_wall(0, 4, 3.0, 0, 2.5), _wall(1, 1.3, 3.12, 1, 1.3))
    assert on_outer_wall(painted, niche, rules) == [False]
