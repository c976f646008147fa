"""Learned line evidence (perception/heuristic/line_evidence.py): image segments carried onto a plane,
kept where the view sees the plane, agreed on across views, and the seams they let the cell split cut.
The segments are plain arrays here (a detector's output); the M-LSD detector itself is tested in
tests/perception/models/test_line_segments.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.camera import look_at
from react3d_core.config.heuristic import HeuristicConfig, LineConfig, OrthoConfig
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.colour_sampling import ColourCalibration, pixel_coords
from react3d_core.perception.heuristic.front_cells import Handle, split_cells
from react3d_core.perception.heuristic.image_fronts import find_image_fronts
from react3d_core.perception.heuristic.line_evidence import (normalised_coords, pick_line_views, rays_to_plane,
                                                             segments_on_plane, view_lines)
from react3d_core.perception.heuristic.orthophoto import Orthophoto
from react3d_core.perception.heuristic.planes import Plane
from react3d_core.raster import Rasterizer
from react3d_core.synthetic.render import RayCaster

# a camera at (0, 0, 1) looking along world +y (OpenCV axes: x right = world +x, y down = world -z)
_LOOK_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 1], [0, 0, 0, 1]])
_K100 = Intrinsics(fx=100.0, fy=100.0, cx=50.0, cy=50.0, width=100, height=100)


def _frame(c2w: np.ndarray, intr: Intrinsics = _K100, fid: str = "frame_000000") -> Frame:
    return Frame(frame_id=fid, rgb=ImageRef(path=Path(f"{fid}.png"), kind="png"), intrinsics=intr, pose=c2w)


def _sheet(x0: float, x1: float, z0: float, z1: float, y: float, step: float, grey: int = 150) -> TriMesh:
    """A flat vertical sheet at ``y`` facing -y, in squares of ``step``."""
    xs, zs = np.arange(x0, x1 + 1e-9, step), np.arange(z0, z1 + 1e-9, step)
    X, Z = np.meshgrid(xs, zs)
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], 1)
    nx = len(xs)
    i = (np.arange(len(zs) - 1)[:, None] * nx + np.arange(nx - 1)[None]).ravel()
    f = np.concatenate([np.stack([i, i + 1, i + nx + 1], 1), np.stack([i, i + nx + 1, i + nx], 1)])
    return TriMesh(v, f, np.full((len(v), 3), grey, np.uint8))


def _merge(*meshes: TriMesh) -> TriMesh:
    off = np.cumsum([0] + [m.n_vertices for m in meshes[:-1]])
    return TriMesh(np.concatenate([m.vertices for m in meshes]), np.concatenate([m.faces + o for m, o in zip(meshes, off)]),
                   np.concatenate([m.colors for m in meshes]))


def _plane_y2() -> Plane:
    """The plane y = 2 facing the camera (-y), u = +x, over x in [-1, 1], z in [0, 2]."""
    return Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), -2.0, np.zeros(0, np.int64),
                 (-1.0, 1.0), (0.0, 2.0), 4.0)


def _ortho(plane: Plane, res: float) -> Orthophoto:
    w = int(round((plane.extent_u[1] - plane.extent_u[0]) / res))
    h = int(round((plane.extent_v[1] - plane.extent_v[0]) / res))
    return Orthophoto(plane, np.ones((h, w, 3), np.float32), np.ones((h, w), np.int32), plane.extent_u[0],
                      plane.extent_v[1], res)


def test_normalised_coords_invert_pixel_coords() -> None:
    """Pixel -> normalised under a calibration (scale 0.9, shift 8, -5 px at 640 px) and back: the same pixel;
    at 320 px width the shift counts half."""
    f = _frame(_LOOK_Y, Intrinsics(fx=300.0, fy=310.0, cx=160.0, cy=120.0, width=320, height=240))
    c = ColourCalibration(0.9, 8.0, -5.0)
    x, y = np.array([10.0, 160.0, 300.5]), np.array([5.0, 120.0, 230.0])
    xn = normalised_coords(x, y, f, 320, 240, c)
    # by hand for the middle pixel: (160 - 160 - 8 * 0.5) / (0.9 * 300), (120 - 120 + 5 * 0.5) / (0.9 * 310)
    assert xn[1] == pytest.approx([-4.0 / 270.0, 2.5 / 279.0])
    bx, by = pixel_coords(xn, f, 320, 240, c)
    assert np.allclose(bx, x, atol=1e-3) and np.allclose(by, y, atol=1e-3)
    # the same camera's image at 640 x 480: intrinsics doubled, shift in full
    xn2 = normalised_coords(np.array([320.0]), np.array([240.0]), f, 640, 480, c)
    assert xn2[0] == pytest.approx([-8.0 / 540.0, 5.0 / 558.0])


def test_rays_meet_the_plane_at_hand_computed_depths() -> None:
    """From (0, 0, 1) looking along +y: the centre ray meets y = 2 at depth 2, the ray (0.2, -0.2) at depth 2
    too (camera depth, not distance), a ray away from the plane never (NaN)."""
    plane = _plane_y2()
    dirs, t = rays_to_plane(np.array([[0.0, 0.0], [0.2, -0.2]]), _LOOK_Y, plane.n, plane.d)
    assert t == pytest.approx([2.0, 2.0])
    assert dirs[1] == pytest.approx([0.2, 1.0, 0.2])  # R @ (0.2, -0.2, 1): x right, -y_cam is up
    behind = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 1], [0, 0, 0, 1]])  # looking along -y
    assert np.isnan(rays_to_plane(np.array([[0.0, 0.0]]), behind, plane.n, plane.d)[1][0])


def test_segments_land_on_the_plane_where_hand_computed() -> None:
    """Pixel (50, 50) -> (u, z) = (0, 1); pixel (70, 30) -> normalised (0.2, -0.2) -> (0.4, 1.4). With the
    colour focal scaled by 2 the same pixels are half as far from the centre: (0.2, 1.2)."""
    plane = _plane_y2()
    f = _frame(_LOOK_Y)
    seg = np.array([[50.0, 50.0, 70.0, 30.0, 0.9]])
    assert segments_on_plane(seg, f, 100, 100, ColourCalibration(), plane.n, plane.u, plane.d)[0] == \
        pytest.approx([0.0, 1.0, 0.4, 1.4])
    assert segments_on_plane(seg, f, 100, 100, ColourCalibration(2.0), plane.n, plane.u, plane.d)[0] == \
        pytest.approx([0.0, 1.0, 0.2, 1.2])


def test_view_lines_keep_only_what_the_view_sees_of_the_plane() -> None:
    """A wall at y = 2 and a panel 1 m in front of it hiding x in [0.1, 0.7], z below 1.2. A vertical
    segment of the image at x = 0.4 m on the wall from z = 0.6 to 1.6 is kept above the panel only
    (z 1.2 - 1.6, less the margin by the panel's edge); one at x = -0.4 m is kept whole and drawn
    ``tol`` wide; a slanted one is neither vertical nor horizontal; a horizontal one is horizontal."""
    wall = _sheet(-1.0, 1.0, 0.0, 2.0, 2.0, 0.05)
    panel = _sheet(0.1, 0.7, 0.0, 1.2, 1.0, 0.05)
    raster = Rasterizer(_merge(wall, panel))
    intr = Intrinsics(fx=400.0, fy=400.0, cx=320.0, cy=240.0, width=640, height=480)
    f = _frame(_LOOK_Y, intr)
    plane = _plane_y2()
    o = _ortho(plane, 0.01)

    def px(x: float, z: float) -> tuple[float, float]:  # world point on the wall -> pixel (depth 2)
        return 320.0 + 400.0 * x / 2.0, 240.0 - 400.0 * (z - 1.0) / 2.0

    seg = np.array([[*px(0.4, 0.6), *px(0.4, 1.6)],      # vertical, partly behind the panel
                    [*px(-0.4, 0.6), *px(-0.4, 1.6)],    # vertical, in full view
                    [*px(-0.8, 0.4), *px(-0.5, 0.8)],    # slanted 37 deg
                    [*px(-0.9, 1.8), *px(0.9, 1.8)]])    # horizontal along the top
    p = LineConfig(tol=0.02)
    vert, horiz = view_lines(seg, f, 640, 480, ColourCalibration(), o, raster, p, OrthoConfig())
    col = lambda x: int((x - o.u0) / o.res)  # noqa: E731
    row = lambda z: int((o.v_top - z) / o.res)  # noqa: E731
    # the seen segment: rows of z 0.6 .. 1.6 at x = -0.4, 2 px (2 cm) to each side
    rows = np.flatnonzero(vert[:, col(-0.4)])
    assert rows.min() == pytest.approx(row(1.6), abs=1) and rows.max() == pytest.approx(row(0.6), abs=1)
    assert vert[row(1.0), col(-0.4) - 2:col(-0.4) + 3].all() and not vert[row(1.0), col(-0.4) + 4]
    # the half-hidden one: only above the panel's shadow on the wall as the camera sees it (its top edge,
    # z 1.2 at depth 1, lies on the ray to z 1.4 at depth 2)
    rows = np.flatnonzero(vert[:, col(0.4)])
    assert rows.min() == pytest.approx(row(1.6), abs=1) and rows.max() == pytest.approx(row(1.4), abs=1)
    assert not vert[row(1.38):row(0.5), col(0.3):col(0.5)].any()
    assert not vert[:, col(-0.75):col(-0.55)].any() and not horiz[row(0.8):row(0.4), :].any()  # slanted: nothing
    hrows = np.flatnonzero(horiz[:, col(0.0)])
    assert len(hrows) == 5 and abs(hrows.mean() - row(1.8)) <= 1   # the horizontal line, 2 cm each way


def test_views_are_picked_seeing_the_plane_and_spread_apart() -> None:
    """Five cameras in a row 2 m from a wall, all seeing it head on, and one looking away: with two views
    per plane the best (the middle one) and the farthest from it among the good ones are read; the one
    looking away never is; ``max_frames`` 1 keeps the best only."""
    plane = _plane_y2()
    o = _ortho(plane, 0.05)
    intr = Intrinsics(fx=300.0, fy=300.0, cx=320.0, cy=240.0, width=640, height=480)
    frames = [_frame(look_at(np.array([x, 0.0, 1.0]), np.array([x, 2.0, 1.0])), intr, f"frame_{i:06d}")
              for i, x in enumerate((-0.4, -0.2, 0.0, 0.2, 0.3))]
    frames.append(_frame(look_at(np.array([0.0, 0.0, 1.0]), np.array([0.0, -2.0, 1.0])), intr, "frame_000005"))
    picks = pick_line_views([o], frames, LineConfig(views_per_plane=2), OrthoConfig())
    assert picks == [[2, 0]]   # the middle one sees most; -0.4 is farthest from it (0.3 is closer)
    assert pick_line_views([o], frames, LineConfig(views_per_plane=2, max_frames=1), OrthoConfig()) == [[2]]


def _plain_ortho(h: int, w: int, res: float = 0.005) -> Orthophoto:
    plane = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.zeros(0, np.int64),
                  (0.0, w * res), (0.0, h * res), w * h * res * res)
    rng = np.random.default_rng(0)
    img = np.full((h, w, 3), 1.0, np.float32) + rng.normal(0, 0.004, (h, w, 3)).astype(np.float32)
    return Orthophoto(plane, img, np.full((h, w), 5, np.int32), 0.0, h * res, res)


def test_a_learned_line_cuts_a_cell_the_brightness_does_not() -> None:
    """A plain 1.2 x 0.7 m panel (no seam in the colours): one cell. With a learned vertical line at
    column 100 over 80 % of its height: two cells cut there. A line over only half the height
    (``lines.span`` 0.6) does not cut."""
    h, w = 140, 240
    o, cov, cfg = _plain_ortho(h, w), np.ones((h, w), bool), HeuristicConfig()
    assert len(split_cells(o, cov, [], cfg)) == 1
    vert, horiz = np.zeros((h, w), bool), np.zeros((h, w), bool)
    vert[14:126, 99:102] = True
    cells = sorted(split_cells(o, cov, [], cfg, (vert, horiz)), key=lambda c: c.c0)
    assert len(cells) == 2 and cells[0].c1 == 100 and cells[1].c0 == 101
    assert cells[0].seam_cuts == 1 and cells[0].cut_sides == 1
    half = np.zeros((h, w), bool)
    half[35:105, 99:102] = True
    assert len(split_cells(o, cov, [], cfg, (half, horiz))) == 1


def test_a_learned_seam_crosses_a_bar_handle_but_not_along_one() -> None:
    """A horizontal bar handle across column 100 (two bars joined over a gap) does not stop a learned
    vertical cut there; a vertical bar handle along column 100 does; without learned lines the bar
    blocks every cut through it (the cell stays whole)."""
    h, w = 140, 240
    o, cov, cfg = _plain_ortho(h, w), np.ones((h, w), bool), HeuristicConfig()
    vert, horiz = np.zeros((h, w), bool), np.zeros((h, w), bool)
    vert[5:135, 99:102] = True
    across = Handle((60, 20, 140, 26), True, np.array([[60, 20]]))
    cells = sorted(split_cells(o, cov, [across], cfg, (vert, horiz)), key=lambda c: c.c0)
    assert [c.c1 for c in cells][:1] == [100] and len(cells) == 2
    assert [len(c.handles) for c in cells] == [1, 0]   # centred on the cut column: the nearest cell, the left
    along = Handle((97, 40, 104, 100), False, np.array([[97, 40]]))
    assert len(split_cells(o, cov, [along], cfg, (vert, horiz))) == 1
    assert len(split_cells(o, cov, [across], cfg)) == 1


def test_between_two_handles_the_learned_line_places_the_cut() -> None:
    """Two handles (0.15 m and 0.75 m) and no seam in the colours: the cut goes half-way between them
    (0.45 m); a learned line at 0.6 m moves it there."""
    h, w = 140, 240
    o, cov, cfg = _plain_ortho(h, w), np.ones((h, w), bool), HeuristicConfig()
    hs = [Handle((27, 40, 33, 100), False, np.array([[27, 40]])), Handle((147, 40, 153, 100), False, np.array([[147, 40]]))]
    plain = sorted(split_cells(o, cov, hs, cfg), key=lambda c: c.c0)
    assert len(plain) == 2 and plain[0].c1 == pytest.approx(90, abs=1)
    vert = np.zeros((h, w), bool)
    vert[:, 119:122] = True
    # the line spans the cell, so the guillotine split takes it before the handle split (same place)
    learned = sorted(split_cells(o, cov, hs, cfg, (vert, np.zeros((h, w), bool))), key=lambda c: c.c0)
    assert len(learned) == 2 and learned[0].c1 == 120
    short = np.zeros((h, w), bool)
    short[50:140, 119:122] = True  # 64 % of the height: short of the guillotine's chunks, enough between handles
    between = sorted(split_cells(o, cov, hs, cfg, (short, np.zeros((h, w), bool))), key=lambda c: c.c0)
    assert len(between) == 2 and between[0].c1 == 120


def _two_door_scene():  # noqa: ANN202
    """A 1.2 x 0.7 m flat red run of two doors meeting at x = 0.6 with no seam in the colours (only a
    learned detector's line says where they meet), handles at x = 0.15 and 0.75; five views."""
    def paint(x: np.ndarray, z: np.ndarray) -> np.ndarray:
        c = np.tile(np.array([170, 40, 40], np.uint8), (len(x), 1))
        for hx in (0.15, 0.75):
            c[(np.abs(x - hx) < 0.012) & (z > 0.35) & (z < 0.55)] = (225, 225, 225)
        return c
    front = _sheet(0.0, 1.2, 0.1, 0.8, 0.0, 0.006)
    front = TriMesh(front.vertices, front.faces, paint(front.vertices[:, 0], front.vertices[:, 2]))
    wall = _sheet(-0.5, 1.7, 0.0, 2.0, 0.6, 0.05, 200)
    mesh = _merge(front, wall)
    caster = RayCaster(mesh)
    W, H = 480, 360
    K = np.array([[400.0, 0, 240], [0, 400.0, 180], [0, 0, 1]])
    frames, images, rng = [], {}, np.random.default_rng(1)
    for i, ex in enumerate((-0.3, 0.1, 0.6, 1.1, 1.5)):
        c2w = look_at(np.array([ex, -1.6, 1.0]), np.array([0.6, 0.0, 0.45]))
        fid = f"frame_{i:06d}"
        images[fid] = caster.rgb(caster.cast(K, c2w, W, H), rng)
        frames.append(Frame(frame_id=fid, rgb=ImageRef(path=Path(f"{fid}.png"), kind="png"),
                            intrinsics=Intrinsics.from_K(K, W, H), pose=c2w))
    return mesh, frames, images


def _seam_detector(frames: list[Frame], images: dict[str, np.ndarray]):  # noqa: ANN202
    """A stand-in for the line detector: the segment the seam x = 0.6, z 0.12 .. 0.78 makes in each image
    (projected by hand with the frame's pose and intrinsics), found by matching the image it is given."""
    by_image = {id(img): f for f in frames for fid, img in images.items() if fid == f.frame_id}

    def detect(img: np.ndarray) -> np.ndarray:
        f = by_image[id(img)]
        ends = np.array([[0.6, 0.0, 0.12], [0.6, 0.0, 0.78]])
        pc = ends @ f.w2c[:3, :3].T + f.w2c[:3, 3]
        K = f.intrinsics.K
        x, y = K[0, 0] * pc[:, 0] / pc[:, 2] + K[0, 2], K[1, 1] * pc[:, 1] / pc[:, 2] + K[1, 2]
        return np.array([[x[0], y[0], x[1], y[1], 0.9]])
    return detect


def test_image_fronts_meet_at_the_learned_seam_end_to_end() -> None:
    """Two doors whose seam the photos do not show: without learned lines the run is cut half-way between
    the handles (0.45 m); with lines enabled and a detector returning the seam's segment in every view,
    the doors meet at 0.6 m, and the support is there in the plane's grid."""
    mesh, frames, images = _two_door_scene()
    raster = Rasterizer(mesh)
    read = lambda f: images[f.frame_id]  # noqa: E731
    off = find_image_fronts(mesh, frames, raster, read)
    assert off.lines == []
    assert sorted(round(f.extent_u[1], 2) for f in off.fronts)[0] == pytest.approx(0.45, abs=0.03)
    cfg = HeuristicConfig(lines={"enabled": True})
    on = find_image_fronts(mesh, frames, raster, read, cfg, detect_lines=_seam_detector(frames, images))
    fronts = sorted(on.fronts, key=lambda f: f.center[0])
    assert len(fronts) == 2
    assert fronts[0].extent_u[1] == pytest.approx(0.6, abs=0.015) and fronts[1].extent_u[0] == pytest.approx(0.6, abs=0.015)
    i = min(range(len(on.planes)), key=lambda k: abs(on.planes[k].d))   # the doors' plane (y = 0), not the wall
    o, sup = on.orthophotos[i], on.lines[i]
    assert sup.n_views == 5
    col = int((0.6 * np.sign(o.plane.u[0]) - o.u0) / o.res)   # u runs along +x or -x
    assert sup.vert[:, col - 2:col + 3].max() == 5
