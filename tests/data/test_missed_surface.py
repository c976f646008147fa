"""Slabs over surfaces the depth sensor missed (react3d_core/scene_io/missed_surface.py), on hand-made scenes:
a room corner whose scan lacks a black cabinet front except a few sparse returns."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from react3d_core.config.scene_io import MissedSurfaceConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.raster import Rasterizer
from react3d_core.scene_io.missed_surface import (HoleView, MissedPlane, carve, fit_vertical_planes, flat_vertices, hole_share,
                                                  is_layer_of, island_vertices, merge_layers, missed_planes, plane_cells,
                                                  seen_planes, slab_mesh)

W, H = 160, 120
K = np.array([[120.0, 0, 79.5], [0, 120.0, 59.5], [0, 0, 1]])


def _look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Camera-to-world, OpenCV axes (x right, y down, z forward), z up world."""
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0, 0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, y, z], 1)
    T[:3, 3] = eye
    return T


def _box(lo, hi) -> trimesh.Trimesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    b = trimesh.creation.box(extents=hi - lo)
    b.apply_translation((lo + hi) / 2)
    return trimesh.Trimesh(*trimesh.remesh.subdivide_to_size(b.vertices, b.faces, 0.03))


def _scene(top_edge_only: bool = False):
    """A closed room (floor, ceiling, walls; back wall (y = 2) and a black cabinet (x 0.5..1.3, y 1.4..2, z 0..0.8) whose front is at
    y = 1.4. The true scene renders the depth readings (none on the cabinet); the scan lacks the cabinet but
    for a few front patches (its sparse returns), or (``top_edge_only``) for its front's top 4 cm, a line."""
    floor = trimesh.util.concatenate([_box([-1, -1, -0.02], [3, 2, 0]), _box([-1, -1, 2.5], [3, 2, 2.52]),  # floor, ceiling
                                      _box([-1.02, -1, 0], [-1, 2, 2.5]), _box([3, -1, 0], [3.02, 2, 2.5]),
                                      _box([-1, -1.02, 0], [3, -1, 2.5])])  # side and front walls: a closed room
    wall = _box([-1, 2, 0], [3, 2.02, 2.5])
    cab = _box([0.5, 1.4, 0.0], [1.3, 2.0, 0.8])
    true = trimesh.util.concatenate([floor, wall, cab])
    n_bg = len(floor.faces) + len(wall.faces)
    cen = cab.triangles_center
    front = np.isclose(cen[:, 1], 1.4)
    rng = np.random.default_rng(0)
    patch = front & (rng.random(len(cen)) < 0.08)  # ~8 % of the front returned depth
    if top_edge_only:
        patch = front & (cen[:, 2] > 0.76)
    scan = trimesh.util.concatenate([floor, wall, trimesh.Trimesh(cab.vertices, cab.faces[patch])])
    true_r = Rasterizer(TriMesh(true.vertices, true.faces))
    scan_mesh = TriMesh(scan.vertices, scan.faces)
    scan_r = Rasterizer(scan_mesh)
    views = []
    for ex in (-0.4, 0.2, 0.9, 1.6, 2.2):
        for ez in (1.0, 1.6):
            c2w = _look_at(np.array([ex, -0.8, ez]), np.array([0.9, 1.7, 0.4]))
            w2c = np.linalg.inv(c2w)
            t = true_r.render(K, c2w, W, H)
            reading = np.where(t.face_ids >= n_bg, 0.0, t.depth).astype(np.float32)  # black: no return
            views.append(HoleView(K, w2c, scan_r.render(K, c2w, W, H).depth, reading))
    return scan_mesh, scan_r, views


@pytest.fixture(scope="module")
def corner():
    return _scene()


def test_carve_keeps_the_missed_cabinet_and_frees_the_room(corner):
    mesh, _r, views = corner
    cfg = MissedSurfaceConfig()
    lo = mesh.vertices.min(0)
    shape = tuple(int(x) for x in np.ceil((mesh.vertices.max(0) - lo) / cfg.voxel_m))
    occ = carve(views, lo, shape, cfg)
    c = lo + (np.argwhere(occ) + 0.5) * cfg.voxel_m
    inside = (c[:, 0] > 0.55) & (c[:, 0] < 1.25) & (c[:, 1] > 1.45) & (c[:, 2] > 0.05) & (c[:, 2] < 0.75)
    assert inside.mean() > 0.3  # a third of the missed voxels is the cabinet itself...
    # ...and nearly all lie in its footprint grown towards the cameras (few views look at its front obliquely)
    near = (c[:, 0] > 0.3) & (c[:, 0] < 1.5) & (c[:, 1] > 0.9) & (c[:, 2] < 1.0)
    assert near.mean() > 0.9
    probe = np.floor((np.array([[0.9, 0.5, 0.4], [2.5, 1.5, 1.0]]) - lo) / cfg.voxel_m).astype(int)
    assert not occ[tuple(probe.T)].any()  # open room in front of it and beside it: seen free


def test_missed_plane_is_the_cabinet_front(corner):
    mesh, r, views = corner
    cfg = MissedSurfaceConfig(min_returns=10)
    planes = missed_planes(mesh, [], r, cfg, views)
    assert planes, "the cabinet front is missed by the scan and must be found"
    p = max(planes, key=lambda q: q.area)
    assert abs(abs(p.normal[1]) - 1) < 1e-6 and p.normal[1] < 0  # faces the cameras (-y)
    assert abs(p.point[1] - 1.4) < 0.015
    # its region spans the front (0.8 x 0.8 m) within about a voxel on each side
    assert 0.45 < p.area < 0.9


def test_a_line_of_returns_fixes_the_plane_of_the_front_below_it():
    # the black cabinet returns only its front's top edge, a line 0.8 m long and 4 cm tall: too flat for a plane
    # (min_spread_m up) without lines; as a line (min_line_m, the default) it fixes the front's plane, and the region reaches
    # down the missed volume's section to the floor, not only return_reach_m from the line
    mesh, r, views = _scene(top_edge_only=True)
    assert missed_planes(mesh, [], r, MissedSurfaceConfig(min_line_m=0.0), views) == []  # off
    cfg = MissedSurfaceConfig(min_line_m=0.3)
    planes = missed_planes(mesh, [], r, cfg, views)
    assert len(planes) == 1
    p = planes[0]
    assert p.normal[1] < -0.9999 and abs(p.point[1] - 1.4) < 0.01
    rows = np.flatnonzero(p.cells.any(1))
    z_top, z_bottom = p.v_top - rows[0] * p.res, p.v_top - (rows[-1] + 1) * p.res
    assert z_top > 0.75 and z_bottom < 0.8 - cfg.return_reach_m - 0.2  # down to within 0.2 m of the floor
    assert 0.45 < p.area < 0.9


def test_slab_mesh_cells_hand_computed():
    cells = np.zeros((3, 4), bool)
    cells[0:2, 1:4] = True  # 2 rows x 3 columns
    p = MissedPlane(point=np.array([0.0, 1.0, 0.0]), normal=np.array([0.0, -1.0, 0.0]), u=np.array([-1.0, 0.0, 0.0]),
                    u0=0.0, v_top=1.0, res=0.1, cells=cells)
    v, f = slab_mesh(p)
    assert len(v) == 3 * 4 and len(f) == 2 * 6  # shared corners: (2+1) x (3+1)
    assert np.allclose(v[:, 1], 1.0)  # on the plane
    assert np.isclose(v[:, 2].max(), 1.0) and np.isclose(v[:, 2].min(), 0.8)
    assert np.isclose(v[:, 0].max(), -0.1) and np.isclose(v[:, 0].min(), -0.4)  # columns 1..3 along u = -x
    m = TriMesh(v, f)
    assert np.isclose(m.face_areas.sum(), 6 * 0.01)
    assert np.allclose(m.face_normals, [0, -1, 0])  # wound towards the cameras


def test_plane_cells_fills_a_rectangle_of_voxels():
    cfg = MissedSurfaceConfig()
    xs, zs = np.meshgrid(np.arange(0.015, 0.6, 0.03), np.arange(0.015, 0.3, 0.03))
    pts = np.stack([xs.ravel(), np.full(xs.size, 2.0), zs.ravel()], 1)
    pts = pts[~((np.abs(pts[:, 0] - 0.3) < 0.04) & (np.abs(pts[:, 2] - 0.15) < 0.04))]  # a hole: filled
    p = plane_cells(pts, np.array([0.0, 2.0, 0.0]), np.array([0.0, -1.0, 0.0]), cfg)
    assert p is not None
    assert abs(p.area - 0.6 * 0.3) < 0.02
    small = plane_cells(pts[:4], np.array([0.0, 2.0, 0.0]), np.array([0.0, -1.0, 0.0]), cfg)
    assert small is None  # under min_area


def test_returns_are_islands_not_walls():
    wall = _box([0, 0, 0], [2, 0.02, 2])  # 4 m² each side: one connected surface
    chip = _box([3, 0, 0], [3.1, 0.01, 0.1])  # a 0.1 x 0.1 m patch: ~0.02 m² of surface
    m = trimesh.util.concatenate([wall, chip])
    isl = island_vertices(TriMesh(m.vertices, m.faces), 0.1)
    assert not isl[:len(wall.vertices)].any() and isl[len(wall.vertices):].all()


def _plane(y: float, x0: float, x1: float, z0: float, z1: float, n_returns: int, res: float = 0.05) -> MissedPlane:
    w, h = int(round((x1 - x0) / res)), int(round((z1 - z0) / res))
    return MissedPlane(point=np.array([0.0, y, 0.0]), normal=np.array([0.0, -1.0, 0.0]), u=np.array([-1.0, 0.0, 0.0]),
                       u0=-x1, v_top=z1, res=res, cells=np.ones((h, w), bool), n_returns=n_returns)


def test_merge_layers_keeps_the_plane_with_most_returns():
    cfg = MissedSurfaceConfig(res_m=0.05)
    front = _plane(1.4, 0.0, 0.8, 0.0, 0.8, n_returns=300)
    handles = _plane(1.37, 0.1, 0.7, 0.3, 0.4, n_returns=40)  # 3 cm in front, overlapping
    other = _plane(1.4, 2.0, 2.6, 0.0, 0.8, n_returns=50)  # same plane, elsewhere: its own surface
    far = _plane(1.1, 0.0, 0.8, 0.0, 0.8, n_returns=60)  # 30 cm in front: another surface
    kept = merge_layers([handles, other, front, far], cfg)
    assert len(kept) == 3
    assert kept[0].n_returns == 340 and np.isclose(kept[0].point[1], 1.4)
    assert abs(kept[0].area - 0.64) < 0.05  # the handles' region lay inside the front's
    assert {round(float(p.point[1]), 2) for p in kept[1:]} == {1.4, 1.1}


def test_seen_planes_drops_a_slab_hidden_behind_another(corner):
    _mesh, _r, views = corner
    cfg = MissedSurfaceConfig()
    front = _plane(1.4, 0.5, 1.3, 0.0, 0.8, n_returns=100, res=0.015)
    behind = _plane(1.6, 0.8, 1.0, 0.3, 0.5, n_returns=100, res=0.015)  # inside the cabinet, hidden from every view
    kept = seen_planes([front, behind], views, cfg)
    assert len(kept) == 1 and np.isclose(kept[0].point[1], 1.4)
    assert kept[0].area > 0.5


def test_hole_share_gates_scans_without_missed_surfaces(corner):
    _mesh, _r, views = corner
    one = np.ones((2, 2), np.float32)
    assert hole_share([HoleView(K, np.eye(4), one, one), HoleView(K, np.eye(4), one, np.array([[0, 1], [1, 1]], np.float32))]) == 0.125
    assert hole_share([HoleView(K, np.eye(4), np.array([[0, 1], [0, 1]], np.float32), None)]) == 0.5  # no depth: scan holes
    assert hole_share(views) > MissedSurfaceConfig().min_hole_share  # the black cabinet fills much of the views


def _returns(rng: np.random.Generator) -> np.ndarray:
    """A black base unit's returns on its front y = 1.4 (x 0..0.9, z 0.1..0.8: a few patches), a column of handle
    returns 3 cm in front of it, and two stray ones 12 cm out at its far end."""
    face = np.stack([rng.uniform(0.0, 0.9, 60), np.full(60, 1.4) + rng.normal(0, 0.003, 60), rng.uniform(0.1, 0.8, 60)], 1)
    handles = np.stack([rng.uniform(0.40, 0.47, 40), np.full(40, 1.37) + rng.normal(0, 0.003, 40), rng.uniform(0.2, 0.7, 40)], 1)
    stray = np.array([[0.88, 1.28, 0.5], [0.89, 1.28, 0.6]])
    return np.concatenate([face, handles, stray])


def test_a_handle_column_is_a_layer_of_its_front():
    cfg = MissedSurfaceConfig(res_m=0.05)
    front = _plane(1.4, 0.0, 0.9, 0.1, 0.8, n_returns=60)
    P = _returns(np.random.default_rng(2))
    t = np.radians(11.6)
    turned = MissedPlane(point=np.array([0.43, 1.37, 0.0]), normal=np.array([-np.sin(t), -np.cos(t), 0.0]),
                         u=np.array([-np.cos(t), np.sin(t), 0.0]), u0=-0.5, v_top=0.8, res=0.05, cells=np.ones((14, 20), bool),
                         n_returns=42, returns=P[60:])
    assert is_layer_of(turned, front, cfg)  # 40 + 2 returns, all within 15 cm of the front and over it
    out = MissedPlane(turned.point, turned.normal, turned.u, turned.u0, turned.v_top, turned.res, turned.cells, 42,
                      P[60:] - [0, 0.3, 0])  # the same returns 30 cm out: another surface
    assert not is_layer_of(out, front, cfg)
    side = MissedPlane(turned.point, np.array([-1.0, 0.0, 0.0]), turned.u, turned.u0, turned.v_top, turned.res,
                       turned.cells, 42, P[60:])  # facing at right angles: a side, not a layer
    assert not is_layer_of(side, front, cfg)
    kept = merge_layers([turned, front], cfg)
    assert len(kept) == 1 and kept[0].n_returns == 102 and np.isclose(kept[0].point[1], 1.4)
    assert front.n_returns == 60  # the input planes are not changed
    assert not is_layer_of(turned, front, cfg.model_copy(update={"layer_share": 0.0}))  # off


def _chip(centre, normal, size: float = 0.04) -> trimesh.Trimesh:
    """A square patch of scan surface (two triangles) facing ``normal``: one island of returns."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    a = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    c = np.asarray(centre, float)
    v = np.array([c + size / 2 * (sa * a + sb * b) for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    if np.dot(np.cross(v[1] - v[0], v[2] - v[0]), n) < 0:
        f = f[:, ::-1]
    return trimesh.Trimesh(v, f, process=False)


def test_islands_facing_up_or_down_are_flat():
    # the area-weighted normal's vertical part: 1 for a worktop chip, 1 for a cabinet bottom's (facing down), 0 for
    # a front's, cos 45 deg = 0.707 for one tilted half-way, 0 for a closed handle box (its faces' normals cancel)
    chips = [_chip([0, 0, 0.9], [0, 0, 1]), _chip([1, 0, 0.9], [0, 0, -1]), _chip([2, 0, 0.5], [0, -1, 0]),
             _chip([3, 0, 0.5], [0, -1, 1])]
    handle = _box([4, 0, 0.5], [4.12, 0.02, 0.52])
    parts = chips + [handle]
    m = trimesh.util.concatenate(parts)
    owner = np.repeat(np.arange(len(parts)), [len(p.vertices) for p in parts])
    tm = TriMesh(m.vertices, m.faces)
    flat = flat_vertices(tm, 0.8)
    assert [bool(flat[owner == k].all()) for k in range(len(parts))] == [True, True, False, False, False]
    assert [bool(flat[owner == k].any()) for k in range(len(parts))] == [True, True, False, False, False]
    assert flat_vertices(tm, 0.7)[owner == 3].all()  # 0.707 >= 0.7: facing up enough
    assert not flat_vertices(tm, 1.0).any()  # 1: off
    assert island_vertices(tm, 0.1).all()  # every piece is small: all are returns, flat or not


def test_a_worktop_sheet_leaves_only_the_front_returns():
    # a black base run's front at y = 0.57 returns a sparse column of chips under a dark worktop (z 0.9, y 0..0.6)
    # that returns a dense sheet of chips all over it: the planes are fitted to the front's chips alone
    rng = np.random.default_rng(3)
    front = [_chip([x, 0.57, z], [0, 1, 0], 0.03) for x, z in zip(rng.uniform(1.9, 2.2, 25), rng.uniform(0.1, 0.85, 25))]
    sheet = [_chip([x, y, 0.9], [0, 0, 1], 0.03) for x, y in zip(rng.uniform(0.5, 3.6, 400), rng.uniform(0.0, 0.6, 400))]
    m = trimesh.util.concatenate(front + sheet)
    tm = TriMesh(m.vertices, m.faces)
    cams = np.array([[2.5, 3.0, 1.5], [1.5, 3.0, 1.5]])
    cfg = MissedSurfaceConfig(flat_island_nz=0.8)
    returns = island_vertices(tm, cfg.max_island_m2) & ~flat_vertices(tm, cfg.flat_island_nz)
    assert returns.sum() == 4 * len(front) and not returns[4 * len(front):].any()  # the front's chips come first
    planes = fit_vertical_planes(tm.vertices[returns], cams, cfg, np.random.default_rng(cfg.seed), cfg.min_returns,
                                 cfg.plane_tol_m)
    point, normal, inl, _ = planes[0]
    assert normal[1] > 0.999 and abs(point[1] - 0.57) < 0.005 and len(inl) == 4 * len(front)


def test_columns_of_returns_make_one_plane():
    # a black wall run returns only its door edges: three dense columns 2 cm wide and 0.6 m tall, 0.6 m apart, on
    # y = 4.09. Paired with their nearest returns (the default), the hypotheses stay inside one column (under a
    # voxel across, or turned any way) and no plane is found; paired with any return within 0.6 m across (opt-in
    # pair_reach_m), the run is one plane
    rng = np.random.default_rng(0)
    P = np.concatenate([np.stack([x + rng.uniform(-0.01, 0.01, 200), 4.09 + rng.normal(0, 0.004, 200),
                                  rng.uniform(1.5, 2.1, 200)], 1) for x in (2.4, 3.0, 3.6)])
    cams = np.array([[3.0, 1.0, 1.5]])
    cfg = MissedSurfaceConfig(pair_reach_m=0.6)
    planes = fit_vertical_planes(P, cams, cfg, np.random.default_rng(cfg.seed), cfg.min_returns, cfg.plane_tol_m)
    assert len(planes) == 1
    point, normal, inl, _ = planes[0]
    assert normal[1] < -0.9999 and abs(point[1] - 4.09) < 0.003 and len(inl) >= 595
    nearest = MissedSurfaceConfig()  # the default: nearest returns
    assert nearest.pair_reach_m == 0.0
    assert fit_vertical_planes(P, cams, nearest, np.random.default_rng(cfg.seed), cfg.min_returns, cfg.plane_tol_m) == []


def _line_cfg() -> MissedSurfaceConfig:
    return MissedSurfaceConfig(min_line_m=0.3)


def test_a_dense_edge_line_is_a_line_and_floor_speckle_is_not():
    # returns along y = 0.57 at z 0.88 over x 1..3 (a base run's top edge), 2 cm tall: a line when dense
    # (a return in every 3 cm step), nothing when 20 speckles spread over the same 2 m (fill under 0.5)
    rng = np.random.default_rng(1)
    cams = np.array([[2.0, 3.0, 1.5]])
    cfg = _line_cfg()

    def edge(n):
        return np.stack([rng.uniform(1.0, 3.0, n), 0.57 + rng.normal(0, 0.002, n), rng.uniform(0.87, 0.89, n)], 1)

    planes = fit_vertical_planes(edge(400), cams, cfg, np.random.default_rng(0), cfg.min_returns, cfg.plane_tol_m, 0.0)
    assert len(planes) == 1 and planes[0].line and abs(planes[0].point[1] - 0.57) < 0.005 and planes[0].normal[1] > 0.999
    assert fit_vertical_planes(edge(400), cams, MissedSurfaceConfig(min_line_m=0.0), np.random.default_rng(0), 15, 0.015, 0.0) == []
    assert fit_vertical_planes(edge(20), cams, cfg, np.random.default_rng(0), 15, 0.015, 0.0) == []
    # the same line turned 20 degrees off the room's walls is no line
    c, s_ = np.cos(np.radians(20)), np.sin(np.radians(20))
    turned = edge(400) @ np.array([[c, s_, 0], [-s_, c, 0], [0, 0, 1]])
    assert fit_vertical_planes(turned, cams, cfg, np.random.default_rng(0), 15, 0.015, 0.0) == []


def test_strips_of_a_returns_sheet_are_no_lines_but_its_front_edge_may_be():
    # a dark worktop returns chips all over it (z 0.9, y 0..0.6): any vertical plane holds a strip of them; a strip
    # with returns more than line_gap_m in front of it is a piece of the sheet, so only lines at its front edge
    # (within line_gap_m of y = 0.6) are kept
    rng = np.random.default_rng(2)
    sheet = np.stack([rng.uniform(1.0, 3.0, 3000), rng.uniform(0.0, 0.6, 3000), rng.normal(0.9, 0.002, 3000)], 1)
    cfg = _line_cfg()
    planes = fit_vertical_planes(sheet, np.array([[2.0, 3.0, 1.5]]), cfg, np.random.default_rng(0), 15, 0.015, 0.0)
    assert all(p.line and p.point[1] > 0.6 - cfg.line_gap_m - 0.015 for p in planes)
    assert len(planes) <= 2


def test_room_axis_is_the_walls_azimuth():
    # two walls of a room turned 30.3 degrees (faces facing 30.3 and 120.3 degrees) and a small chip facing 75:
    # the axis is the walls' azimuth modulo 90
    walls = trimesh.util.concatenate([_box([0, 0, 0], [4, 0.02, 2.5]), _box([0, 0, 0], [0.02, 3, 2.5])])
    walls.apply_transform(trimesh.transformations.rotation_matrix(np.radians(30.3), [0, 0, 1]))
    chip = _chip([1.0, 1.0, 1.0], [np.cos(np.radians(75)), np.sin(np.radians(75)), 0], 0.03)
    m = trimesh.util.concatenate([walls, chip])
    tm = TriMesh(m.vertices, m.faces)
    from react3d_core.scene_io.missed_surface import _on_axis, _pieces, room_axis_deg
    axis = room_axis_deg(tm, _pieces(tm), 0.1)
    assert axis is not None and abs(axis - 30.3) < 0.01
    assert _on_axis(np.array([np.cos(np.radians(-59.0)), np.sin(np.radians(-59.0)), 0]), 30.5, 5.0)  # 90 - 59 = 31
    assert not _on_axis(np.array([np.cos(np.radians(40.0)), np.sin(np.radians(40.0)), 0]), 30.5, 5.0)
    assert _on_axis(np.array([1.0, 0, 0]), None, 5.0)
    assert room_axis_deg(TriMesh(chip.vertices, chip.faces), _pieces(TriMesh(chip.vertices, chip.faces)), 0.1) is None
