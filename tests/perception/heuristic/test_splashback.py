"""Fronts standing on a worktop, flush with the wall behind it, are splash-back (hand-built scenes)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import SplashbackConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.splashback import on_worktop


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
