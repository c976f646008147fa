"""Fronts standing on a worktop, flush with the wall behind it, are splash-back (hand-built scenes)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import SplashbackConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.splashback import on_worktop, wall_behind_share


def _quad(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned rectangle (one of the extents is flat), two triangles facing +z or -y."""
    if z0 == z1:   # horizontal, facing up
        v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0]])
    else:          # vertical in x-z at y0, facing -y
        v = np.array([[x0, y0, z0], [x0, y0, z1], [x1, y0, z1], [x1, y0, z0]])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _mesh(*quads: tuple[np.ndarray, np.ndarray]) -> TriMesh:
    vs, fs, off = [], [], 0
    for v, f in quads:
        vs.append(v)
        fs.append(f + off)
        off += len(v)
    return TriMesh(np.concatenate(vs), np.concatenate(fs))


def _front(x0: float, x1: float, z0: float, z1: float, y: float = 0.6) -> Front:
    """A front in the wall plane y = ``y``, facing -y (the room)."""
    return Front(facet=-1, handle_facets=[], center=np.array([(x0 + x1) / 2, y, (z0 + z1) / 2]),
                 n_out=np.array([0.0, -1.0, 0.0]), u=np.array([1.0, 0.0, 0.0]), extent_u=(x0, x1), extent_v=(z0, z1))


def test_front_on_a_worktop_is_splashback_and_wall_cabinet_or_base_door_is_not() -> None:
    """A 0.6 m deep worktop at 0.9 m runs along a wall (y = 0.6, the room at y < 0.6); the floor is at 0.
    - a panel from 0.92 to 1.40 m flush with the wall over the worktop: splash-back (dropped);
    - a wall cabinet from 1.45 to 2.15 m: its bottom is 0.55 m above the worktop (kept);
    - a base-unit door from 0.1 to 0.85 m: the floor in front of it is below ``min_z`` (kept);
    - the same panel where the worktop stops short (a 0.6 m gap under it): nothing under its edge (kept)."""
    mesh = _mesh(_quad(0.0, 2.0, 0.0, 0.6, 0.9, 0.9),        # worktop x 0..2, y 0..0.6 at z 0.9
                 _quad(-1.0, 4.0, -2.0, 0.6, 0.0, 0.0),      # floor
                 _quad(0.0, 4.0, 0.6, 0.6, 0.0, 2.4))        # the wall
    fronts = [_front(0.2, 1.2, 0.92, 1.40), _front(0.2, 1.2, 1.45, 2.15), _front(0.2, 0.8, 0.1, 0.85),
              _front(2.6, 3.4, 0.92, 1.40)]
    assert on_worktop(fronts, mesh, SplashbackConfig()) == [True, False, False, False]


def test_worktop_must_cover_the_strip() -> None:
    """Only a 5 cm deep ledge in front of the panel (less than ``cover`` of the 0.3 m strip): kept;
    a 0.2 m deep shelf (2/3 of the strip): dropped. Hand-computed: strip 0.3 m x 1.0 m = 0.3 m²,
    ledge 0.05 x 1.0 = 0.05 m² < 0.2 x 0.3 = 0.06; shelf 0.2 x 1.0 = 0.2 m² >= 0.06."""
    f = [_front(0.0, 1.0, 1.0, 1.5)]
    rules = SplashbackConfig(min_z=0.5, band=0.08, reach=(0.0, 0.3), cover=0.2)
    ledge = _mesh(_quad(0.0, 1.0, 0.55, 0.6, 1.0, 1.0))
    shelf = _mesh(_quad(0.0, 1.0, 0.4, 0.6, 1.0, 1.0))
    assert on_worktop(f, ledge, rules) == [False]
    assert on_worktop(f, shelf, rules) == [True]


def test_rules_from_config_and_switch() -> None:
    from react3d_core.config import PipelineConfig

    h = PipelineConfig().perception.heuristic
    assert h.splashback.enabled and (h.splashback.min_z, h.splashback.cover) == (0.5, 0.2)
    off = PipelineConfig().with_overrides({"perception": {"heuristic": {"splashback": {"enabled": False}}}}).perception.heuristic
    assert off.splashback.enabled is False


def test_run_below_stands_for_a_worktop_the_mesh_lacks() -> None:
    """A black worktop returned no depth: the mesh holds the wall (y = 0.6) and the floor only. In front of the
    wall stands a base run whose door (y = 0.0, x 0.2-0.8, 0.1-0.88 m) is 0.6 m ahead of the wall (inside
    ``run_depth`` 0.45-0.8):
    - a panel on the wall from 0.92 m (0.04 above the door's top, within ``band`` 0.08), x 0.5-1.1, overlapping
      the door across by 0.3 m: splash-back (dropped); with ``run_depth`` (0, 0) it is kept;
    - the same panel at x 1.0-1.6, past the door's end: kept;
    - a wall cabinet from 1.45 m: 0.57 above the door's top, kept;
    - a microwave's door standing on the worktop 0.2 m behind the door (y = 0.2, 0.92-1.2 m): kept."""
    mesh = _mesh(_quad(-1.0, 4.0, -2.0, 0.6, 0.0, 0.0), _quad(0.0, 4.0, 0.6, 0.6, 0.0, 2.4))
    door = _front(0.2, 0.8, 0.1, 0.88, y=0.0)
    fronts = [door, _front(0.5, 1.1, 0.92, 1.40), _front(1.0, 1.6, 0.92, 1.40), _front(0.2, 0.8, 1.45, 2.15),
              _front(0.3, 0.7, 0.92, 1.2, y=0.2)]
    assert SplashbackConfig().run_depth == (0.45, 0.8)
    assert on_worktop(fronts, mesh, SplashbackConfig()) == [False, True, False, False, False]
    assert on_worktop(fronts, mesh, SplashbackConfig(run_depth=(0.0, 0.0))) == [False] * 5


def test_run_below_allows_for_the_worktops_thickness() -> None:
    """The panel's bottom lies above the run's top edge by the worktop's thickness and the gap under it. Door top
    0.88 m; ``band`` 0.08, ``worktop_rise`` 0.07: the panel's bottom may lie from 0.80 to 1.03 m (exclusive).
    - bottom 0.98 (0.10 above the door: a 4 cm worktop on a 6 cm gap): splash-back;
    - bottom 1.02 (0.14 above): splash-back; bottom 1.05 (0.17 above): kept;
    - with ``worktop_rise`` 0 the bound is 0.96: the panel at 0.98 is kept."""
    mesh = _mesh(_quad(-1.0, 4.0, -2.0, 0.6, 0.0, 0.0), _quad(0.0, 4.0, 0.6, 0.6, 0.0, 2.4))
    door = _front(0.2, 0.8, 0.1, 0.88, y=0.0)
    fronts = [door, _front(0.3, 0.7, 0.98, 1.3), _front(0.3, 0.7, 1.02, 1.3), _front(0.3, 0.7, 1.05, 1.3)]
    rules = SplashbackConfig()
    assert (rules.band, rules.worktop_rise) == (0.08, 0.07)
    assert on_worktop(fronts, mesh, rules) == [False, True, True, False]
    assert on_worktop(fronts[:2], mesh, SplashbackConfig(worktop_rise=0.0)) == [False, False]


def _grid_wall(x0: float, x1: float, y: float, z0: float, z1: float, step: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """A wall at y = ``y`` facing -y made of ``step`` squares (the ring test reads face centroids)."""
    xs, zs = np.arange(x0, x1 + 1e-9, step), np.arange(z0, z1 + 1e-9, step)
    X, Z = np.meshgrid(xs, zs)
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], -1)
    nx = len(xs)
    i = (np.arange(len(zs) - 1)[:, None] * nx + np.arange(nx - 1)[None, :]).ravel()
    f = np.concatenate([np.stack([i, i + nx + 1, i + nx], -1), np.stack([i, i + 1, i + nx + 1], -1)])
    return v, f


def test_appliance_pushed_back_on_a_worktop_stands_in_front_of_the_wall() -> None:
    """A 0.6 m worktop at 0.9 m (y 0..0.6) against a wall at y = 0.6. A microwave pushed back stands on it, its door
    at y = 0.2 (0.2 m of worktop in front of it, 0.4 m in front of the wall), x 0.5-0.9, 0.92-1.20 m.
    Its strip 0.03-0.33 m in front holds worktop over y 0-0.17: 0.17 x 0.4 = 0.068 m² of the 0.3 x 0.4 = 0.12 m²
    strip (57 % >= ``cover`` 20 %), so the worktop test alone takes it for splash-back. Its ring 0.3 m wide round the
    sides and top is (0.4 + 0.6) x (0.28 + 0.3) - 0.4 x 0.28 = 0.468 m², all of it wall 0.4 m behind the door
    (within ``wall_behind`` 0.2-1.0): share ~1 >= ``wall_share`` 0.1, kept. A panel flush with the wall over the same
    worktop has its wall 0 m behind it: share 0, dropped. With ``wall_ring`` 0 the microwave is dropped too."""
    top = _grid_wall(0.0, 2.0, 0.0, 0.0, 0.6)  # the same grid laid flat: y -> z, z -> y, facing up
    top = (top[0][:, [0, 2, 1]] + [0.0, 0.0, 0.9], top[1])
    mesh = _mesh(top, _quad(-1.0, 4.0, -2.0, 0.6, 0.0, 0.0), _grid_wall(-0.5, 2.5, 0.6, 0.0, 2.0))
    assert mesh.face_normals[0, 2] > 0.99
    microwave, panel = _front(0.5, 0.9, 0.92, 1.2, y=0.2), _front(1.2, 1.8, 0.92, 1.4, y=0.6)
    rules = SplashbackConfig()
    assert (rules.wall_ring, rules.wall_behind, rules.wall_share) == (0.3, (0.2, 1.0), 0.1)
    assert wall_behind_share(microwave, mesh, rules) > 0.9
    assert wall_behind_share(panel, mesh, rules) == 0.0
    assert on_worktop([microwave, panel], mesh, rules) == [False, True]
    assert on_worktop([microwave, panel], mesh, SplashbackConfig(wall_ring=0.0)) == [True, True]
