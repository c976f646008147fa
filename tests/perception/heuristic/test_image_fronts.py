"""Fronts found in the colour frames: plane voting, robust fusion, seam/handle cells, and a seamless
mesh whose fronts only the photos show (the real-scan situation, built by hand)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.camera import look_at
from react3d_core.config.heuristic import (ClutterConfig, FloorConfig, HandleConfig, HeuristicConfig, PlanesConfig,
                                           SeamConfig)
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.facets import planar_facets
from react3d_core.perception.heuristic.front_cells import find_handles, split_cells
from react3d_core.perception.heuristic.fronts import find_fronts
from react3d_core.perception.heuristic.image_fronts import (coarse_faces, coverage_from_faces, find_image_fronts,
                                                             modelled_surface, slab_faces)
from react3d_core.perception.heuristic.orthophoto import ColourCalibration, Orthophoto, _nanmedian
from react3d_core.perception.heuristic.plane_surface import PlaneSurface, cast_surface, flat_surface
from react3d_core.perception.heuristic.planes import surface_samples, vertical_planes
from react3d_core.raster import Rasterizer
from react3d_core.synthetic.render import RayCaster
from tests.perception.heuristic.flat_orthos import flat_ortho


def _grid_mesh(x0: float, x1: float, z0: float, z1: float, y: float, step: float, colour) -> TriMesh:  # noqa: ANN001
    """A flat vertical sheet at ``y`` (no seams), facing -y, coloured per vertex by ``colour(x, z)``."""
    xs = np.arange(x0, x1 + 1e-9, step)
    zs = np.arange(z0, z1 + 1e-9, step)
    X, Z = np.meshgrid(xs, zs)
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], 1)
    nx = len(xs)
    i = np.arange(len(zs) - 1)[:, None] * nx + np.arange(nx - 1)[None]
    i = i.ravel()
    f = np.concatenate([np.stack([i, i + 1, i + nx + 1], 1), np.stack([i, i + nx + 1, i + nx], 1)])
    return TriMesh(v, f, colour(v[:, 0], v[:, 2]))


def _merge(*meshes: TriMesh) -> TriMesh:
    off = np.cumsum([0] + [m.n_vertices for m in meshes[:-1]])
    return TriMesh(np.concatenate([m.vertices for m in meshes]), np.concatenate([m.faces + o for m, o in zip(meshes, off)]),
                   np.concatenate([m.colors for m in meshes]))


def test_nanmedian_hand_computed() -> None:
    st = np.array([[1.0, np.nan], [3.0, 2.0], [2.0, np.nan], [np.nan, np.nan]], np.float32)[:, :, None]  # (V=4, 2, 1)
    st = st.reshape(4, 1, 2)
    out = _nanmedian(st)
    assert out.shape == (1, 2)
    assert out[0, 0] == pytest.approx(2.0)      # median of 1, 3, 2
    assert out[0, 1] == pytest.approx(2.0)      # one view only
    assert _nanmedian(np.full((3, 1, 1), np.nan, np.float32))[0, 0] == 0.0  # no view: 0


def test_vertical_planes_split_l_shape_and_turned_cabinet() -> None:
    """An L of two walls meeting at a rounded corner is two planes; a unit turned by 9 degrees is its own."""
    grey = lambda x, z: np.full((len(x), 3), 150, np.uint8)  # noqa: E731
    back = _grid_mesh(0.0, 2.0, 0.0, 0.9, 2.0, 0.02, grey)                       # n = -y, y = 2
    side = _grid_mesh(0.0, 1.5, 0.0, 0.9, 0.0, 0.02, grey)
    side = TriMesh(side.vertices[:, [1, 0, 2]], side.faces, side.colors)   # x = 0 plane, facing +x (the swap mirrors)
    a = np.radians(9.0)
    unit = _grid_mesh(0.0, 0.8, 0.5, 1.0, 0.0, 0.02, grey)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    unit = TriMesh(unit.vertices @ R.T + [1.0, 3.5, 0.0], unit.faces, unit.colors)
    planes = vertical_planes(_merge(back, side, unit), np.array([1.0, 1.0, 1.2]), PlanesConfig(), max_tilt=0.3, min_area=0.2)
    normals = sorted((tuple(np.round(p.n, 2)), round(p.area, 1)) for p in planes)
    assert len(planes) == 3, normals
    by_area = sorted(planes, key=lambda p: -p.area)
    assert abs(by_area[0].n @ [0, -1, 0]) > 0.99 and by_area[0].area == pytest.approx(1.8, abs=0.05)
    assert abs(by_area[1].n @ [1, 0, 0]) > 0.99 and by_area[1].area == pytest.approx(1.35, abs=0.05)
    assert np.degrees(np.arccos(abs(by_area[2].n @ [0, 1, 0]))) == pytest.approx(9.0, abs=1.5)
    for p in planes:  # normals face the camera centre
        mid = p.to_world(np.mean(p.extent_u), np.mean(p.extent_v))
        assert np.dot(p.n, np.array([1.0, 1.0, 1.2]) - mid) > 0


def _ortho(img: np.ndarray, res: float = 0.005) -> Orthophoto:
    return flat_ortho(img, res)


def _splat_surface(o: Orthophoto, cen: np.ndarray, nrm: np.ndarray) -> PlaneSurface:
    """The ``PlaneSurface`` a cast would give for small patches at ``cen`` facing ``nrm``: each patch's
    offset in front of the plane in its pixel (the front-most where two share one), NaN elsewhere."""
    h, w = o.n_views.shape
    p = o.plane
    dn = cen @ p.n - p.d
    c = np.floor((cen @ p.u - o.u0) / o.res).astype(int)
    r = np.floor((o.v_top - cen[:, 2]) / o.res).astype(int)
    front, cos = np.full((h, w), np.nan, np.float32), np.full((h, w), np.nan, np.float32)
    for k in np.argsort(dn):  # the front-most patch last
        front[r[k], c[k]], cos[r[k], c[k]] = dn[k], nrm[k] @ p.n
    return PlaneSurface(np.where(np.abs(front) <= PlanesConfig().offset_tol, front, np.nan), front, cos)


def test_cells_split_at_seams_and_between_handles() -> None:
    """A 1.2 x 0.7 m panel (5 mm px): a dark seam at 0.4 m, a bright horizontal reflection line without
    handles on both sides, and handles: one in the left cell, two side by side in the right part (the
    seam between them is missing) -> three cells, one handle each; the reflection does not cut."""
    h, w = 140, 240
    rng = np.random.default_rng(0)
    img = np.full((h, w, 3), 1.0, np.float32) + rng.normal(0, 0.004, (h, w, 3)).astype(np.float32)
    img[:, 79:81] *= 0.85                      # seam at 0.4 m
    img[70:72, :] *= 0.9                       # a reflected table edge (horizontal, whole width)
    for c0 in (20, 110, 190):                  # horizontal bar handles near the top, 0.2 m x 0.02 m
        img[15:19, c0:c0 + 40] = [1.8, 1.8, 1.8]
    o = _ortho(img)
    cov = np.ones((h, w), bool)
    p = HeuristicConfig()
    handles = find_handles(o, cov, p)
    assert len(handles) == 3 and all(hd.horizontal for hd in handles)
    cells = sorted(split_cells(o, cov, handles, p), key=lambda c: c.c0)
    assert [len(c.handles) for c in cells] == [1, 1, 1]
    assert abs(cells[0].c1 - 80) <= 2                       # the seam
    assert 150 <= cells[1].c1 <= 190                        # between the two right handles
    assert all(c.r0 == 0 and c.r1 == h for c in cells)      # the reflection line did not cut


def test_find_fronts_no_candidate_gives_no_front() -> None:
    """A mesh with no door-sized vertical facet (a floor) must give 0 fronts, not an einsum error."""
    floor = _grid_mesh(0.0, 1.0, 0.0, 1.0, 0.0, 0.1, lambda x, z: np.full((len(x), 3), 100, np.uint8))
    floor = TriMesh(floor.vertices[:, [0, 2, 1]], floor.faces, floor.colors)     # z = 0 plane
    facets = planar_facets(floor)
    assert find_fronts(floor, facets, np.ones(facets.n, bool), np.array([0.5, 0.5, 1.5])) == []


def _seamless_cabinet_scene(scale: float = 1.0, shift_px: tuple[float, float] = (0.0, 0.0),
                            per_view: list[tuple[float, float, float]] | None = None):  # noqa: ANN202
    """A 1.2 x 0.7 m flat run of two doors, no seam in the mesh: the gap and the handles exist only in
    the vertex colours (like a TSDF scan, where the photos show what the mesh lost). Rendered from five
    views; colour images may be rendered with a focal ``scale`` and a principal-point shift (an
    unregistered colour camera), and each view with its own further (scale, dx, dy) in ``per_view``
    (colour not synchronised with depth)."""
    def paint(x: np.ndarray, z: np.ndarray) -> np.ndarray:
        c = np.tile(np.array([170, 40, 40], np.uint8), (len(x), 1))
        c[np.abs(x - 0.6) < 0.006] = (60, 20, 20)                                  # the seam
        for hx in (0.45, 0.75):                                                    # vertical bar handles
            c[(np.abs(x - hx) < 0.012) & (z > 0.35) & (z < 0.55)] = (225, 225, 225)
        return c
    front = _grid_mesh(0.0, 1.2, 0.1, 0.8, 0.0, 0.006, paint)
    wall = _grid_mesh(-0.5, 1.7, 0.0, 2.0, 0.6, 0.05, lambda x, z: np.full((len(x), 3), 200, np.uint8))
    mesh = _merge(front, wall)
    caster = RayCaster(mesh)
    W, H = 480, 360
    K = np.array([[400.0, 0, 240], [0, 400.0, 180], [0, 0, 1]])
    Kc = K.copy()
    Kc[:2, :2] *= scale
    Kc[0, 2] += shift_px[0]
    Kc[1, 2] += shift_px[1]
    frames, images = [], {}
    rng = np.random.default_rng(1)
    for i, ex in enumerate((-0.3, 0.1, 0.6, 1.1, 1.5)):
        c2w = look_at(np.array([ex, -1.6, 1.0]), np.array([0.6, 0.0, 0.45]))
        fid = f"frame_{i:06d}"
        Kv = Kc.copy()
        if per_view is not None:
            s_i, dx_i, dy_i = per_view[i]
            Kv[:2, :2] *= s_i
            Kv[0, 2] += dx_i
            Kv[1, 2] += dy_i
        images[fid] = caster.rgb(caster.cast(Kv, c2w, W, H), rng)
        frames.append(Frame(frame_id=fid, rgb=ImageRef(path=Path(f"{fid}.png"), kind="png"),
                            intrinsics=Intrinsics.from_K(K, W, H), pose=c2w))
    return mesh, frames, images


@pytest.mark.parametrize("scale, shift, opt", [(1.0, (0.0, 0.0), {}), (0.92, (6.0, -4.0), {}),
                                              (1.0, (0.0, 0.0), {"image": {"surface_rays": True}, "ortho": {"pick_spread": True}})])
def test_seamless_mesh_splits_into_two_doors_from_the_images(scale: float, shift: tuple[float, float], opt: dict) -> None:
    """Also with the plane surface from rays and the views picked for spread (both opt-in)."""
    mesh, frames, images = _seamless_cabinet_scene(scale, shift)
    facets = planar_facets(mesh)
    assert facets.n <= 4  # the mesh alone has no seam between the doors
    res = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id], HeuristicConfig(**opt))
    fronts = sorted(res.fronts, key=lambda f: f.center[0])
    assert len(fronts) == 2, [(np.round(f.center, 2), f.w, f.h) for f in fronts]
    for f, (u0, u1) in zip(fronts, ((0.0, 0.6), (0.6, 1.2))):
        cu = 0.5 * (f.extent_u[0] + f.extent_u[1])
        assert abs(abs(cu) - 0.5 * (u0 + u1)) < 0.04 and abs(f.w - 0.6) < 0.06 and abs(f.h - 0.7) < 0.05
        assert f.kind == "door" and f.articulation.joint_type == "revolute"
        assert abs(f.articulation.axis[2]) > 0.99
        hinge_x = f.articulation.origin[0]
        # the handle is near the inner edges (0.45 / 0.75): hinges on the outer edges (0 / 1.2)
        assert min(abs(hinge_x - 0.0), abs(hinge_x - 1.2)) < 0.04
    if scale != 1.0:
        assert res.calibration.scale == pytest.approx(scale, abs=0.03)
    else:
        assert res.calibration == ColourCalibration(before=res.calibration.before, after=res.calibration.after)


def test_coarse_faces_by_area_weighted_median_size() -> None:
    """n right triangles with 1 cm legs (5e-5 m2 each) and two with 3 cm legs (9e-4 m2 together): the
    area-weighted median size is 3 cm while the small ones hold under half the area (n = 17: 8.5e-4 of
    1.75e-3), 1 cm once they hold over half (n = 19: 9.5e-4 of 1.85e-3)."""
    def tris(n_small: int) -> TriMesh:
        legs = [0.01] * n_small + [0.03, 0.03]
        v, f = [], []
        for k, leg in enumerate(legs):
            o = np.array([0.1 * k, 0.0, 0.0])
            v += [o, o + [leg, 0, 0], o + [0, 0, leg]]
            f.append([3 * k, 3 * k + 1, 3 * k + 2])
        return TriMesh(np.array(v), np.array(f))
    for n, coarse in ((17, True), (19, False)):
        m = tris(n)
        assert coarse_faces(m, np.arange(m.n_faces), 0.015) is coarse
        assert coarse_faces(m, np.arange(m.n_faces), 0.0) is False  # 0: never
    assert coarse_faces(tris(17), np.arange(17), 0.015) is False  # the small faces alone


def test_modelled_surface_by_exact_normals() -> None:
    """Two triangles facing -y exactly and one tilted 1 degree, 0.02 m2 each: 2/3 of the area is a group of
    two faces with one exact normal (modelled at share 0.5, not at 0.7); a lone face is no group, whatever
    its area; 1 mm of noise on every vertex (a scan) leaves no two normals equal."""
    v = np.array([[0, 0, 0], [0.2, 0, 0], [0, 0, 0.2], [0.3, 0, 0], [0.5, 0, 0], [0.3, 0, 0.2],
                  [0.6, 0, 0], [0.8, 0, 0], [0.6, 0.2 * np.tan(np.radians(1.0)), 0.2]], float)
    m = TriMesh(v, np.array([[0, 1, 2], [3, 4, 5], [6, 7, 8]]))
    assert modelled_surface(m, np.arange(3), 0.5) and not modelled_surface(m, np.arange(3), 0.7)
    assert not modelled_surface(m, np.arange(3), 0.0)  # 0: never
    assert not modelled_surface(m, np.array([0, 2]), 0.4)  # one face of each normal: no group
    noisy = TriMesh(v + np.random.default_rng(0).normal(0, 0.001, v.shape), m.faces)
    assert not modelled_surface(noisy, np.arange(3), 0.1)


def test_a_decimated_scan_gives_the_fronts_of_the_fine_one() -> None:
    """The photos are of the world; the scan is the same two doors in 2.5 cm faces (a decimated fused mesh).
    Their centroids lie farther apart than the coverage closing (2 cm), so painted by centroids the plane
    comes out mostly uncovered and no front is cut; its coverage read from rays gives both doors."""
    _fine, frames, images = _seamless_cabinet_scene()
    grey = lambda x, z: np.full((len(x), 3), 128, np.uint8)  # noqa: E731
    rng = np.random.default_rng(0)
    coarse = _merge(_grid_mesh(0.0, 1.2, 0.1, 0.8, 0.0, 0.025, grey), _grid_mesh(-0.5, 1.7, 0.0, 2.0, 0.6, 0.05, grey))
    coarse = TriMesh(coarse.vertices + rng.normal(0, 0.001, coarse.vertices.shape) * [0, 1, 0], coarse.faces,
                     coarse.colors)  # a scan's 1 mm depth noise: no exactly shared normals
    assert not modelled_surface(coarse, np.arange(coarse.n_faces), 0.5)
    read = lambda f: images[f.frame_id]  # noqa: E731
    res = find_image_fronts(coarse, frames, Rasterizer(coarse), read, HeuristicConfig())
    fronts = sorted(res.fronts, key=lambda f: f.center[0])
    assert len(fronts) == 2, [(np.round(f.center, 2), f.w, f.h) for f in fronts]
    for f, cu in zip(fronts, (0.3, 0.9)):
        assert abs(abs(0.5 * (f.extent_u[0] + f.extent_u[1])) - cu) < 0.04 and abs(f.w - 0.6) < 0.06
        assert f.kind == "door"
    off = find_image_fronts(coarse, frames, Rasterizer(coarse), read, HeuristicConfig(image={"rays_face_edge": 0.0}))
    assert len(off.fronts) < 2
    flat = _merge(_grid_mesh(0.0, 1.2, 0.1, 0.8, 0.0, 0.025, grey), _grid_mesh(-0.5, 1.7, 0.0, 2.0, 0.6, 0.05, grey))
    modelled = find_image_fronts(flat, frames, Rasterizer(flat), read, HeuristicConfig())  # exact: left to the mesh
    assert len(modelled.fronts) < 2


def _registration_errors(res, per_view: list[tuple[float, float, float]], W: int = 480, H: int = 360) -> np.ndarray:  # noqa: ANN001
    """Per view, px error of where its correction maps three pose-projection pixels against where the
    renderer put them, less the error common to all views (the consensus may sit anywhere the scene
    calibration leaves it)."""
    k = W / 640.0
    errs = []
    for i, (s, dx, dy) in enumerate(per_view):
        c = res.registration.get(i, res.calibration)
        e = []
        for u, v in ((100, 80), (240, 180), (380, 280)):
            want = (s * (u - W / 2) + W / 2 + dx, s * (v - H / 2) + H / 2 + dy)
            got = (c.scale * (u - W / 2) + W / 2 + c.dx * k, c.scale * (v - H / 2) + H / 2 + c.dy * k)
            e.append(np.subtract(got, want))
        errs.append(e)
    errs = np.array(errs)  # (views, points, 2)
    return np.linalg.norm(errs - errs.mean(0, keepdims=True), axis=-1).max(1)


_REGISTER = HeuristicConfig(registration={"sigmas_px": (12.0, 6.0, 3.0, 1.5)})


def test_each_view_is_registered_onto_the_others() -> None:
    """Colour not synchronised with depth: each view's colour is off by its own scale and shift (up to
    6 px). The per-view registration brings every view within a pixel of the others, and the doors are
    still split; with registration off the views stay several pixels apart (the check can fail)."""
    per_view = [(1.0, 0.0, 0.0), (0.97, 5.0, -3.0), (1.03, -6.0, 2.0), (1.0, 3.0, 6.0), (0.98, -4.0, -5.0)]
    mesh, frames, images = _seamless_cabinet_scene(per_view=per_view)
    res = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id], cfg=_REGISTER)
    assert sorted(res.registration) == list(range(5))
    err = _registration_errors(res, per_view)
    assert err.max() < 0.6, err
    assert len(res.fronts) == 2
    res_off = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id])  # the default: off
    assert _registration_errors(res_off, per_view).max() > 4.0


def test_registration_leaves_registered_colour_alone() -> None:
    """Views that already agree end where they started (within a tenth of a pixel)."""
    mesh, frames, images = _seamless_cabinet_scene()
    res = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id], cfg=_REGISTER)
    assert _registration_errors(res, [(1.0, 0.0, 0.0)] * 5).max() < 0.1
    for c in res.registration.values():
        assert abs(c.scale - 1) < 1e-3 and abs(c.dx) < 0.2 and abs(c.dy) < 0.2


def test_orthophoto_params_are_in_the_config() -> None:
    """An override of ``perception.heuristic.ortho.resolution`` reaches the orthophotos the image path fuses."""
    from react3d_core.config import PipelineConfig

    cfg = PipelineConfig().with_overrides({"perception": {"heuristic": {"ortho": {"resolution": 0.006},
                                                                        "seams": {"span": 0.5}}}})
    h = cfg.perception.heuristic
    assert h.ortho.resolution == 0.006 and h.seams.span == 0.5
    assert PipelineConfig().perception.heuristic.ortho.resolution == 0.004
    mesh, frames, images = _seamless_cabinet_scene()
    res = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id], cfg=h)
    assert res.orthophotos and {o.res for o in res.orthophotos} == {0.006}


def test_frames_without_colour_fall_back_to_the_mesh_with_one_warning(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """Colour frames that cannot be read give one warning line and the mesh-only fronts, never a crash."""
    import logging

    from react3d_core.data.frames import SceneInput
    from react3d_core.data.mesh import save_mesh
    from react3d_core.perception.heuristic import HeuristicModel

    mesh, frames, _ = _seamless_cabinet_scene()
    mesh_path = save_mesh(tmp_path / "mesh.ply", mesh)
    scene = SceneInput(scene_id="s", root=tmp_path, mesh_path=mesh_path, frames=tuple(frames), source_format="generic")
    with caplog.at_level(logging.WARNING, logger="react3d.perception"):
        model = HeuristicModel(scene)
    assert model.image is None and model.fronts == []   # the seamless mesh alone shows no front
    warnings = [r for r in caplog.records if r.name == "react3d.perception"]
    assert len(warnings) == 1 and "mesh only" in warnings[0].getMessage()


def test_split_between_handles_ends_on_overlapping_bars() -> None:
    """Two handle blobs whose boxes overlap, with seam evidence where the cut lands on the first
    centre's integer column: the cut separates nothing and must end (it recursed until RecursionError
    on a laser-scanned wardrobe)."""
    from react3d_core.perception.heuristic.front_cells import Cell, Handle, _split_handles

    h1 = Handle((100, 10, 201, 16), True, np.array([[100, 10]]))   # centre x 150.5
    h2 = Handle((160, 40, 212, 46), True, np.array([[160, 40]]))   # centre x 186, box overlaps h1's
    c = Cell(0, 0, 300, 200, [h1, h2])
    ev = np.zeros((200, 300), bool)
    ev[:, 150] = True
    cells = _split_handles(c, ev, ev, np.ones((200, 300), bool), 20, (np.ones((200, 300)),) * 2, SeamConfig())
    assert sum(len(x.handles) for x in cells) == 2 and all(x.handles for x in cells)


def test_dip_scores_hand_computed() -> None:
    """A flat panel (brightness 1.0) with one column at 0.9: that column dips 0.1 below its neighbours'
    median; the noise (MAD of the dips) is 0, floored at 1e-3, so it scores 100; every other column 0.
    A line less than 30 % covered scores 0 whatever its brightness."""
    from react3d_core.perception.heuristic.front_cells import _dip_scores

    g = np.ones((40, 60))
    g[:, 30] = 0.9
    g[:, 45] = 0.5
    cov = np.ones((40, 60), bool)
    cov[:30, 45] = False                       # column 45: 10 of 40 pixels covered
    z = _dip_scores(g, cov, 0, 5, SeamConfig())
    assert z[30] == pytest.approx(100.0)
    assert z[45] == 0.0 and np.count_nonzero(z) == 1


def test_straight_seam_found_through_wood_grain() -> None:
    """The synthetic generator's own wood grain (vertical rings, ±10 %) fused like an orthophoto (nine
    views, each off by up to a pixel, averaged over 4 mm pixels, median) makes dark vertical lines in
    many columns, so valley counts cannot tell a seam. A straight 2 px seam 30 % dark along the whole
    height (what the photo renderer's crevices give) is found by its line median at column 100; the
    same panel without the seam is not cut."""
    import cv2

    from react3d_core.synthetic.materials import WOOD, albedo_modulation

    h, w, res, ss = 160, 200, 0.004, 4
    X, Z = np.meshgrid(np.arange(w * ss) * res / ss + 0.3, 1.2 - np.arange(h * ss) * res / ss)
    pts = np.stack([X, np.full_like(X, 2.0), Z])
    nrm = np.broadcast_to(np.array([0.0, -1.0, 0.0])[:, None, None], pts.shape)
    fine = albedo_modulation(pts, nrm, np.full(X.shape, WOOD))

    def fused(img: np.ndarray) -> Orthophoto:
        rng = np.random.default_rng(0)
        views = []
        for _ in range(9):
            dx, dy = rng.uniform(-1, 1, 2) * ss
            m = np.float32([[1, 0, dx], [0, 1, dy]])
            shifted = cv2.warpAffine(img, m, (img.shape[1], img.shape[0]), borderMode=cv2.BORDER_REFLECT)
            views.append(cv2.resize(shifted, (w, h), interpolation=cv2.INTER_AREA))
        return _ortho(np.repeat(np.median(views, 0)[:, :, None], 3, 2), res)

    cov = np.ones((h, w), bool)
    p = HeuristicConfig()
    assert len(split_cells(fused(fine), cov, [], p)) == 1
    seam = fine.copy()
    seam[:, 100 * ss:102 * ss] *= 0.7
    cells = split_cells(fused(seam), cov, [], p)
    assert len(cells) == 2 and abs(min(c.c1 for c in cells) - 101) <= 1


def test_outline_fills_handle_shadow_notch() -> None:
    """A front whose handle's scanning shadow is a notch open to its top edge (3 px wide, 3 deep):
    the outline fills it (plane on both sides within 4 px) but adds nothing outside the front."""
    from react3d_core.perception.heuristic.image_fronts import cov_outline

    cov = np.zeros((10, 12), bool)
    cov[2:8, 2:10] = True
    cov[2:5, 5:8] = False
    out = cov_outline(cov, 4)
    expected = np.zeros((10, 12), bool)
    expected[2:8, 2:10] = True
    assert np.array_equal(out, expected)


def test_colour_step_cuts_a_door_leaf_out_of_a_wall() -> None:
    """A brown door leaf (0.9 m) in a pale wall, no dark seam at its edges, a lever handle: the cells are
    cut at the two colour steps, so the leaf is one cell holding the handle; a plain wall is not cut."""
    h, w = 420, 500                            # 5 mm px: 2.1 m x 2.5 m
    rng = np.random.default_rng(1)
    wall = np.array([1.1, 1.15, 1.05], np.float32)
    img = np.tile(wall, (h, w, 1)) + rng.normal(0, 0.01, (h, w, 3)).astype(np.float32)
    assert len(split_cells(_ortho(img), np.ones((h, w), bool), [], HeuristicConfig())) == 1
    img[:, 160:340] = np.array([0.55, 0.4, 0.3], np.float32) + rng.normal(0, 0.01, (h, 180, 3)).astype(np.float32)
    img[200:206, 300:330] = 1.6                # lever handle near the leaf's right edge
    o = _ortho(img)
    cov = np.ones((h, w), bool)
    handles = find_handles(o, cov, HeuristicConfig())
    cells = split_cells(o, cov, handles, HeuristicConfig())
    leaf = [c for c in cells if c.handles]
    assert len(leaf) == 1 and abs(leaf[0].c0 - 160) <= 2 and abs(leaf[0].c1 - 340) <= 2


def test_thin_lines_are_structure_not_clutter() -> None:
    """At 1 cm per pixel, min length 0.15 m (15 px), max width 0.02 m: a 1 px x 60 px line and a 2 px x
    40 px vertical line are structure; a 20 x 20 px blob (a poster) and a 1 x 10 px dash are not."""
    from react3d_core.perception.heuristic.image_fronts import thin_lines

    m = np.zeros((80, 100), bool)
    m[10, 5:65] = True            # long thin horizontal line
    m[20:60, 80:82] = True        # long thin vertical line, 2 px wide
    m[40:60, 20:40] = True        # filled blob
    m[70, 50:60] = True           # short dash
    lines = thin_lines(m, 0.01, 0.15, 0.02)
    assert lines[10, 5:65].all() and lines[20:60, 80:82].all()
    assert not lines[40:60, 20:40].any() and not lines[70, 50:60].any()
    assert not thin_lines(m, 0.01, 0.0, 0.02).any()   # 0 turns it off


def test_clutter_share_against_the_cell_colour() -> None:
    """A plain red door cell whose local-background map flags a band along one edge (the neighbour's
    colour leaks into the 12 cm median) is not cluttered by its own colour: share min(0.3, 0.0) = 0.
    With a blue poster over 30 % of the cell it is: both measures say 0.3."""
    from react3d_core.perception.heuristic.front_cells import Cell
    from react3d_core.perception.heuristic.image_fronts import _clutter_share

    h, w = 50, 40
    img = np.tile(np.array([1.4, 0.3, 0.3], np.float32), (h, w, 1))
    o = _ortho(img, 0.01)
    cell = Cell(0, 0, w, h)
    band = np.zeros((h, w), bool)
    band[:, :12] = True                                   # 12 of 40 columns: 0.3
    seen = np.ones((h, w), bool)
    none = np.zeros((h, w), bool)
    min_px = ClutterConfig().median_min_px
    assert _clutter_share(o, cell, band, seen, None, min_px) == pytest.approx(0.3)
    assert _clutter_share(o, cell, band, seen, (0.12, none), min_px) == pytest.approx(0.0)
    img[:, :12] = [0.3, 0.3, 1.4]                         # a poster where the band is
    o = _ortho(img, 0.01)
    assert _clutter_share(o, cell, band, seen, (0.12, none), min_px) == pytest.approx(0.3)


def test_colour_step_beats_a_weaker_frame_line() -> None:
    """Two shaker doors of different colours meet at column 100 (a colour step, no dark gap); inside
    the right door its frame casts a dark line at column 116. With ``step_over_dip`` the cut is the
    colour step (the doors' edge); without it, the dark line wins and the cut lands 16 px inside the door."""
    h, w = 160, 200
    rng = np.random.default_rng(3)
    img = np.empty((h, w, 3), np.float32)
    img[:, :100] = [0.6, 1.2, 0.6]                        # green door
    img[:, 100:] = [1.3, 1.2, 0.5]                        # yellow door
    img += rng.normal(0, 0.01, img.shape).astype(np.float32)
    img[:, 116] *= 0.8                                    # the frame's shadow line
    o = _ortho(img, 0.004)
    cov = np.ones((h, w), bool)
    on = HeuristicConfig(cells={"min_side": 0.12}, seams={"step_over_dip": True})
    off = HeuristicConfig(cells={"min_side": 0.12}, seams={"step_over_dip": False})
    cuts_on = sorted({c.c0 for c in split_cells(o, cov, [], on)} - {0})
    cuts_off = sorted({c.c0 for c in split_cells(o, cov, [], off)} - {0})
    assert cuts_on and abs(cuts_on[0] - 100) <= 2, cuts_on
    assert cuts_off and abs(cuts_off[0] - 117) <= 2, cuts_off


def test_enclosed_handle_shadows_hand_computed() -> None:
    """Unseen holes in a 0.6 x 0.4 m plane (5 mm px): a horizontal 0.2 x 0.04 m hole inside (a bar's
    shadow seen from below) is kept; a vertical hole (a gap between fronts), a 1 cm thin horizontal one
    and one open to the outline's border are not."""
    from react3d_core.perception.heuristic.image_fronts import enclosed_holes

    h, w = 80, 120
    outline = np.zeros((h, w), bool)
    outline[5:75, 5:115] = True
    seen = outline.copy()
    seen[60:68, 20:60] = False   # 0.2 m x 0.04 m, enclosed: a handle's shadow
    seen[10:50, 80:86] = False   # vertical: 0.2 m tall, 0.03 m wide
    seen[20:22, 20:60] = False   # horizontal but 1 cm thin
    seen[70:75, 70:100] = False  # reaches the outline's bottom border
    holes = enclosed_holes(seen, outline, 0.005, HandleConfig().shadow_min_thick)
    expected = np.zeros((h, w), bool)
    expected[60:68, 20:60] = True
    assert np.array_equal(holes, expected)


def test_seen_near_reaches_a_set_distance_hand_computed() -> None:
    """1 cm px, reach 2 cm (OpenCV's 5 x 5 ellipse: 2 px straight up, down and sideways, 1 px up or down
    when 2 px sideways, not (2, 1)): a 3 px hole in what the views see (a handle's shadow)
    is filled, the seen part grows by 2 px (what the depth-edge erosion took off), and a stretch farther
    than that from any seen pixel (a wall behind a cabinet) stays out."""
    from react3d_core.perception.heuristic.image_fronts import seen_near

    seen = np.zeros((30, 60), bool)
    seen[5:25, 5:30] = True
    seen[12:15, 12:15] = False   # 3 x 3 px hole inside
    got = seen_near(seen, 0.01, 0.02)
    expected = np.zeros((30, 60), bool)
    expected[3:27, 5:30] = True  # 2 px up and down
    expected[4:26, 3:32] = True  # 2 px left and right, and 1 px up or down with them
    assert np.array_equal(got, expected)
    assert not got[:, 33:].any() and not got[28:].any()
    assert np.array_equal(seen_near(seen, 0.01, 0.0), seen)


def test_protrusion_map_grows_the_splat_by_one_pixel() -> None:
    """One outward face 3 cm in front of the plane (4 mm px) marks the 3 x 3 px around its centroid's
    pixel; a face 1 cm in front (under the 1.2 cm minimum) or facing away marks nothing."""
    from react3d_core.perception.heuristic.image_fronts import protrusion_from_faces, protrusion_map

    o = _ortho(np.ones((50, 60, 3), np.float32), res=0.004)        # plane y = 0, facing -y; v_top = 0.2
    cen = np.array([[0.1 + 0.002, -0.03, 0.2 - 0.1 - 0.002],      # pixel (row 25, col 25)
                    [0.05, -0.01, 0.1], [0.15, -0.03, 0.1]])
    nrm = np.array([[0.0, -1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    m = protrusion_map(o, _splat_surface(o, cen, nrm), HandleConfig(), 0.0, PlanesConfig().offset_tol)
    expected = np.zeros((50, 60), bool)
    expected[24:27, 24:27] = True
    assert np.array_equal(m, expected)
    # the same faces splatted by centroid (image.surface_rays off) mark the same pixels
    assert np.array_equal(protrusion_from_faces(o, cen, nrm, HandleConfig(), 0.0, PlanesConfig().offset_tol), expected)


def test_standing_bar_in_the_mesh_is_a_handle() -> None:
    """At 4 mm px: a standing bar handle in the mesh, two centroid columns wide (the splat of a 1.5 cm bar
    of 5 mm faces), 16 cm long, is one vertical handle. Before, the colour's 3 x 3 opening erased it."""
    from react3d_core.perception.heuristic.image_fronts import protrusion_map

    h, w, res = 150, 200, 0.004
    o = _ortho(np.ones((h, w, 3), np.float32), res=res)
    cov = np.ones((h, w), bool)
    zs = 0.6 - (np.arange(30, 70) + 0.5) * res                     # rows 30-69
    cen = np.array([[(c + 0.5) * res, -0.03, z] for c in (50, 51) for z in zs])
    bar = protrusion_map(o, _splat_surface(o, cen, np.tile([0.0, -1.0, 0.0], (len(cen), 1))), HandleConfig(), 0.0,
                         PlanesConfig().offset_tol)
    hs = find_handles(o, cov, HeuristicConfig(), None, bar, cov)
    assert len(hs) == 1 and not hs[0].horizontal
    assert hs[0].box == (49, 29, 53, 71)


def test_side_cover_hand_computed() -> None:
    """Bands of 2 px along the long sides of a box; pixels beyond the grid count as uncovered."""
    from react3d_core.perception.heuristic.front_cells import _side_cover

    ref = np.zeros((10, 12), bool)
    ref[:, 4:] = True                           # covered from column 4 on
    # vertical box at columns 5-6, rows 2-5: left band columns 3-4 (half covered), right band 7-8 (all)
    assert _side_cover(ref, (5, 2, 2, 4), 2) == pytest.approx((0.5, 1.0))
    # vertical box at columns 0-1: the left band lies beyond the grid (0), the right band 2-3 is uncovered
    assert _side_cover(ref, (0, 2, 2, 4), 2) == pytest.approx((0.0, 0.0))
    # horizontal box at row 0, columns 4-9: above beyond the grid (0), below rows 1-2 covered
    assert _side_cover(ref, (4, 0, 6, 1), 2) == pytest.approx((0.0, 1.0))
    # horizontal box at row 4, columns 2-5: bands above (rows 2-3) and below (rows 5-6) each 2 of 4 columns
    assert _side_cover(ref, (2, 4, 4, 1), 2) == pytest.approx((0.5, 0.5))


def test_ridge_at_the_planes_end_is_no_handle() -> None:
    """A 6 cm x 32 cm ridge in the mesh at a plane's left end (a wall corner, a unit's side: the plane
    on one side only) passes the overall cover test but not ``side_cover`` (0.4, the default); the same bar in the middle
    of the plane stays a handle either way. RedKitchen, stride 5: such a ridge at the end of the tiled
    wall became a door with protrusion_from_surface."""
    h, w, res = 150, 200, 0.004
    o = _ortho(np.ones((h, w, 3), np.float32), res=res)
    cov = np.ones((h, w), bool)
    on, off = HeuristicConfig(handles={"side_cover": 0.4}), HeuristicConfig(handles={"side_cover": 0.0})
    for c0, kept_with in ((0, False), (90, True)):
        bar = np.zeros((h, w), bool)
        bar[40:120, c0:c0 + 15] = True
        assert len(find_handles(o, cov, off, None, bar, cov)) == 1
        assert (len(find_handles(o, cov, on, None, bar, cov)) == 1) == kept_with


def test_protrusion_is_measured_from_the_surface_around() -> None:
    """A wall whose right half lies 1.5 cm in front of its fitted plane (a TSDF wall is not flat), and a
    bar 3 cm in front of that half. Against the plane (``win`` 0, the rule up to heuristic version 13) the
    whole right half is protrusion (1.5 cm > 1.2 cm); against the surface around (``protrusion_from_surface``,
    the default since version 14: 12 cm window) only the bar."""
    from react3d_core.perception.heuristic.image_fronts import protrusion_map

    h, w, res = 100, 200, 0.004
    o = _ortho(np.ones((h, w, 3), np.float32), res=res)            # plane y = 0 facing -y; v_top = 0.4
    cols, rows = np.meshgrid(np.arange(0, w, 2), np.arange(0, h, 2))
    x, z = (cols.ravel() + 0.5) * res, 0.4 - (rows.ravel() + 0.5) * res
    wall = np.stack([x, np.where(cols.ravel() >= 100, -0.015, 0.0), z], 1)
    bar = np.array([[(c + 0.5) * res, -0.015 - 0.03, 0.4 - (r + 0.5) * res] for c in (150, 151) for r in range(30, 70)])
    cen = np.concatenate([wall, bar])
    nrm = np.tile([0.0, -1.0, 0.0], (len(cen), 1))
    surf = _splat_surface(o, cen, nrm)
    plane = protrusion_map(o, surf, HandleConfig(), 0.0, PlanesConfig().offset_tol)
    assert plane[:, 100:].all() and not plane[:, :99].any()
    m = protrusion_map(o, surf, HandleConfig(), 0.12, PlanesConfig().offset_tol)
    assert m[30:70, 150:152].all()
    assert m.sum() == m[28:72, 148:154].sum() and m.sum() <= 44 * 6       # only the bar (closed, grown by 1 px)


def test_local_surface_hand_computed() -> None:
    """Blocks of 2 px, window 3 blocks, a 12 x 12 px grid (6 x 6 blocks). Block (0, 0) holds offsets
    0.01, 0.03, 0.02 (median 0.02), block (0, 1) holds 0.05. The window of block (0, 0) lies over 4
    blocks of the grid, 2 of them filled (at least a third): median of 0.02 and 0.05 = 0.035. The window
    of block (1, 1) lies over 9 blocks, 2 filled (under a third): the plane, 0. Far blocks: no faces, 0."""
    from react3d_core.perception.heuristic.image_fronts import _local_surface

    dn = np.array([0.01, 0.03, 0.02, 0.05])
    r = np.array([0, 1, 1, 0])
    c = np.array([0, 0, 1, 3])
    s = _local_surface(dn, r, c, (12, 12), 2, 3)
    assert s.shape == (12, 12)
    assert np.allclose(s[0:2, 0:2], 0.035)              # block (0, 0)
    assert np.allclose(s[0:2, 2:4], 0.035)              # block (0, 1): 6 blocks inside, 2 filled
    assert np.allclose(s[2:4, 2:4], 0.0)                # block (1, 1)
    assert np.allclose(s[6:, 6:], 0.0)


def test_handle_found_from_its_shadow_alone() -> None:
    """A plain front whose bar handle left only an unseen hole (no colour anywhere): with the hole as
    handle evidence find_handles reports one horizontal handle there; without it, none."""
    from react3d_core.perception.heuristic.image_fronts import enclosed_holes

    h, w = 140, 100
    img = np.full((h, w, 3), 1.0, np.float32)
    o = _ortho(img)
    o.n_views[110:118, 30:70] = 0  # 0.2 x 0.04 m, 0.11 m above the bottom edge
    cov = np.ones((h, w), bool)
    p = HeuristicConfig()
    assert find_handles(o, cov, p) == []
    hs = find_handles(o, cov, p, None, enclosed_holes(o.n_views > 0, cov, o.res, p.handles.shadow_min_thick), cov)
    assert len(hs) == 1 and hs[0].horizontal and hs[0].box == (30, 110, 70, 118)


def test_handle_shadows_only_above_eye_level() -> None:
    """The same enclosed hole counts only when it lies wholly above the row of the cameras' height."""
    from react3d_core.perception.heuristic.image_fronts import enclosed_holes

    outline = np.ones((40, 60), bool)
    outline[[0, -1], :] = False
    seen = outline.copy()
    seen[20:28, 10:50] = False
    thick = HandleConfig().shadow_min_thick
    assert enclosed_holes(seen, outline, 0.005, thick, row_limit=28).sum() == 8 * 40
    assert enclosed_holes(seen, outline, 0.005, thick, row_limit=27).sum() == 0


def test_shadow_in_cell_picks_the_largest_shadow_centred_in_it() -> None:
    """Shadows centred in the cell [0,50)x[0,40): the larger one's pixels come back as points on the
    plane (5 mm px, plane y=0 facing -y, v_top 0.2 m); a shadow centred outside is ignored; no shadow -> None."""
    from react3d_core.perception.heuristic.front_cells import Cell, Handle
    from react3d_core.perception.heuristic.image_fronts import _shadow_in_cell

    o = _ortho(np.ones((40, 100, 3), np.float32))
    small = Handle((5, 30, 25, 34), True, np.array([[c, r] for r in range(30, 34) for c in range(5, 25)]))
    big = Handle((10, 20, 40, 26), True, np.array([[c, r] for r in range(20, 26) for c in range(10, 40)]))
    outside = Handle((45, 5, 95, 15), True, np.array([[c, r] for r in range(5, 15) for c in range(45, 95)]))
    pts = _shadow_in_cell(o, Cell(0, 0, 50, 40), [small, big, outside])
    assert pts.shape == (6 * 30, 3)
    assert np.allclose(pts[0], [10.5 * 0.005, 0.0, 0.2 - 20.5 * 0.005])
    assert _shadow_in_cell(o, Cell(0, 0, 50, 40), []) is None


def test_a_cell_with_a_handle_may_be_more_cluttered() -> None:
    """A 0.5 x 0.7 m cell (1 cm px), 25 % of it off its background (a raised panel's shading): over
    clutter.max_share 0.18, under clutter.max_share_handle 0.3. Holding a handle it is a front; without one (cut on
    all four sides, so the handle is the only difference) it is clutter; at 35 % it is clutter either way."""
    from react3d_core.perception.heuristic.front_cells import Cell, Handle
    from react3d_core.perception.heuristic.image_fronts import _cell_front

    h, w = 70, 50
    o = _ortho(np.ones((h, w, 3), np.float32), 0.01)
    cov = np.ones((h, w), bool)
    clutter = np.zeros((h, w), bool)
    clutter[:, : int(0.25 * w) + 1] = True                  # 13 of 50 columns: 0.26
    # faces of the plane (y = 0): centroids on a 2 cm lattice over the cell, as (u, z, depth)
    uu, zz = np.meshgrid(np.arange(0.01, 0.5, 0.02), np.arange(0.01, 0.7, 0.02))
    in_plane = np.stack([uu.ravel(), zz.ravel(), np.zeros(uu.size)], 1)
    pix = np.stack(np.meshgrid(np.arange(40, 43), np.arange(20, 40)), -1).reshape(-1, 2)
    handle = Handle((40, 20, 43, 40), False, pix)
    cfg = HeuristicConfig()
    assert cfg.clutter.max_share < 0.26 < cfg.clutter.max_share_handle
    with_handle = Cell(0, 0, w, h, handles=[handle], cut_sides=4)
    without = Cell(0, 0, w, h, handles=[], cut_sides=4)
    assert _cell_front(o, without, cov, np.zeros((h, w), bool), in_plane, cfg, None) is not None
    f = _cell_front(o, with_handle, cov, clutter, in_plane, cfg, None)
    assert f is not None and f.handle_points is not None and abs(f.w - 0.5) < 0.02 and abs(f.h - 0.7) < 0.02
    assert _cell_front(o, without, cov, clutter, in_plane, cfg, None) is None
    clutter[:, : int(0.35 * w)] = True                      # 0.34: over both limits
    assert _cell_front(o, with_handle, cov, clutter, in_plane, cfg, None) is None


def test_a_cut_out_fronts_rim_is_no_clutter() -> None:
    """A 0.32 x 0.24 m raised-panel door (5 mm px: 64 x 48 px) cut out on four sides, its 3 cm rim (6 px: the
    seams and the bevel ring) off the background all round: 3072 - 52 x 36 = 1200 px, 39 % of the cell, over
    clutter.max_share_handle 0.3, so it was clutter; its middle is plain (0 %), so with the rim left out it is a
    front. Not so with the rim rule off, with the cell cut on one side only (its other edges the plane's
    outline: a plinth over the floor line) or with its handle's centre on the rim. The same rim is left out
    of the share of the cell the plane's surface must cover (cells.min_seen)."""
    from react3d_core.perception.heuristic.front_cells import Cell, Handle
    from react3d_core.perception.heuristic.image_fronts import _cell_front

    h, w, res = 48, 64, 0.005
    o = _ortho(np.ones((h, w, 3), np.float32), res)
    cov = np.ones((h, w), bool)
    clutter = np.ones((h, w), bool)
    clutter[6:-6, 6:-6] = False
    assert clutter.sum() == 1200
    uu, zz = np.meshgrid(np.arange(0.005, 0.32, 0.01), np.arange(0.005, 0.24, 0.01))
    in_plane = np.stack([uu.ravel(), zz.ravel(), np.zeros(uu.size)], 1)

    def handle(c: int, r: int) -> Handle:
        pix = np.stack(np.meshgrid(np.arange(c, c + 3), np.arange(r, r + 16)), -1).reshape(-1, 2)
        return Handle((c, r, c + 3, r + 16), False, pix)

    cfg = HeuristicConfig()
    assert round(cfg.clutter.handle_rim / res) == 6
    door = Cell(0, 0, w, h, handles=[handle(50, 16)], cut_sides=4)
    f = _cell_front(o, door, cov, clutter, in_plane, cfg, None)
    assert f is not None and abs(f.w - 0.32) < 0.01 and abs(f.h - 0.24) < 0.01
    assert _cell_front(o, door, cov, clutter, in_plane, HeuristicConfig(clutter={"handle_rim": 0.0}), None) is None
    assert _cell_front(o, Cell(0, 0, w, h, handles=[handle(50, 16)], cut_sides=1), cov, clutter, in_plane, cfg, None) is None
    assert _cell_front(o, Cell(0, 0, w, h, handles=[handle(60, 16)], cut_sides=4), cov, clutter, in_plane, cfg, None) is None
    # the rim's surface missing too (a fused scan's grooves and bevels), and 184 px of the middle: 1688 / 3072
    # = 0.549 covered, under cells.min_seen 0.55; the middle alone 1688 / 1872 = 0.90
    cov[clutter] = False
    cov[10:14, 6:52] = False
    assert abs(cov.mean() - 1688 / 3072) < 1e-9
    assert _cell_front(o, door, cov, clutter, in_plane, cfg, None) is not None
    assert _cell_front(o, door, cov, clutter, in_plane, HeuristicConfig(cells={"seen_rim": False}), None) is None


def _quad(x0: float, x1: float, y0: float, y1: float, z: float) -> TriMesh:
    v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], float)
    return TriMesh(v, np.array([[0, 1, 2], [0, 2, 3]]))


def test_floor_height_hand_computed() -> None:
    """Floor 2 x 2 m in two halves at z = -0.002 (1.5 m²) and +0.004 (2.5 m²), a worktop 1 m² at 0.9 m:
    the lowest 2 cm band holds 4 m² >= 0.5, its area-weighted median is +0.004. Without the floor the
    worktop alone (1 m²) is the floor at 0.5 m², and no floor at 2 m²."""
    from react3d_core.perception.heuristic.image_fronts import floor_height

    floor = _merge(_quad(0, 0.75, 0, 2, -0.002), _quad(0.75, 2, 0, 2, 0.004))
    top = _quad(0, 1, 0, 1, 0.9)
    assert floor_height(_merge(floor, top), FloorConfig(min_area=0.5)) == pytest.approx(0.004)
    assert floor_height(top, FloorConfig(min_area=0.5)) == pytest.approx(0.9)
    assert floor_height(top, FloorConfig(min_area=2.0)) is None
    down = TriMesh(top.vertices, top.faces[:, ::-1])  # facing down: a ceiling, not a floor
    assert floor_height(down, FloorConfig(min_area=0.5)) is None


def test_handle_less_fronts_reaching_the_floor_are_wall() -> None:
    """Beside a room door: plain panels from the floor (bottom 0.00 m) are dropped, a plain drawer on a
    5 cm plinth and a handled door from the floor are kept; with no floor known nothing is dropped."""
    from react3d_core.perception.heuristic.fronts import Front
    from react3d_core.perception.heuristic.image_fronts import off_the_floor

    def front(bottom: float, handle: bool) -> Front:
        f = Front(facet=-1, handle_facets=[], center=np.zeros(3), n_out=np.array([0.0, -1, 0]), u=np.array([1.0, 0, 0]),
                  extent_u=(0.0, 0.6), extent_v=(bottom, bottom + 0.5), faces=np.arange(4))
        f.handle_points = np.zeros((3, 3)) if handle else None
        return f

    wall, drawer, door = front(0.0, False), front(0.05, False), front(0.0, True)
    assert off_the_floor([wall, drawer, door], 0.001, 0.03) == [drawer, door]
    assert off_the_floor([wall, drawer, door], None, 0.03) == [wall, drawer, door]
    # the bottom drawer of a handle-less stack reaches the floor too (a recessed plinth scanned with it)
    assert off_the_floor([wall, drawer, door], 0.001, 0.03, {id(wall)}) == [wall, drawer, door]


def _line_points(theta_deg: float, d: float, t0: float, t1: float, step: float = 0.01) -> np.ndarray:
    """Points of the vertical plane with horizontal normal at ``theta_deg`` and offset ``d``, for tangent
    coordinates t0..t1 (in the xy plane)."""
    th = np.radians(theta_deg)
    n, t = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
    ts = np.arange(t0, t1 + 1e-9, step)
    return d * n + ts[:, None] * t


def test_fit_direction_hand_computed() -> None:
    """A 2.5 m wall turned by 0.5 degrees, a curved door 1-4 cm behind it over 0.8 m, and normals whose
    mean is skewed to 1.5 degrees: the positions give the wall's direction (to the 0.1 degree search step)
    and offset; a piece narrower than 1 m keeps the normals' direction."""
    from react3d_core.perception.heuristic.planes import fit_direction

    wall = _line_points(-89.5, 3.72, 0.0, 2.5)
    door = _line_points(-89.5, 3.75, -0.8, -0.01)
    door = door + np.linspace(0.0, 0.03, len(door))[:, None] * np.array([np.cos(np.radians(-89.5)), np.sin(np.radians(-89.5))])
    xy = np.concatenate([wall, door])
    w = np.ones(len(xy))
    nd = np.array([np.cos(np.radians(-88.5)), np.sin(np.radians(-88.5)), 0.0])
    n, d = fit_direction(xy, w, nd, PlanesConfig(refit_deg=3.0))
    assert np.degrees(np.arctan2(n[1], n[0])) == pytest.approx(-89.5, abs=0.051)
    assert n[2] == 0.0 and np.linalg.norm(n) == pytest.approx(1.0)
    assert d == pytest.approx(3.72, abs=0.006)  # the 1 cm window holding the wall
    narrow = _line_points(-89.5, 3.72, 0.0, 0.9)
    n2, d2 = fit_direction(narrow, np.ones(len(narrow)), nd, PlanesConfig(refit_deg=3.0))
    assert n2 is nd and d2 == pytest.approx(float(np.mean(narrow @ nd[:2])))


def test_fit_direction_keeps_parallel_layers_apart() -> None:
    """A wall with a door leaf 2 cm in front of it along part of its length: turning the plane so that the
    wall's far end meets the leaf piles one 1 cm window higher, but smears both layers; the fit stays
    parallel to both (every layer sharp at once)."""
    from react3d_core.perception.heuristic.planes import fit_direction

    wall = np.concatenate([_line_points(0.0, 0.0, 0.0, 1.2), _line_points(0.0, 0.0, 2.1, 2.7)])
    leaf = _line_points(0.0, 0.02, 1.2, 2.1)
    xy = np.concatenate([wall, leaf])
    n, d = fit_direction(xy, np.ones(len(xy)), np.array([1.0, 0.0, 0.0]), PlanesConfig(refit_deg=3.0, refit_min_gain=1.0))  # any gain
    assert abs(np.degrees(np.arctan2(n[1], n[0]))) < 0.051
    assert d == pytest.approx(0.0, abs=0.006)


def test_vertical_plane_beside_a_curved_door_is_not_turned() -> None:
    """A flat 2.5 m base run beside a curved fridge door: the normals' mean leans towards the curve; with
    the direction refit from positions the plane stays parallel to the run, so both of its ends are
    within 5 mm of it (without, the far end drifts)."""
    grey = lambda x, z: np.full((len(x), 3), 150, np.uint8)  # noqa: E731
    run = _grid_mesh(0.0, 2.5, 0.0, 0.9, 2.0, 0.02, grey)
    fridge = _grid_mesh(-0.8, -0.02, 0.0, 1.8, 2.0, 0.02, grey)
    s = (fridge.vertices[:, 0] + 0.8) / 0.8
    fridge.vertices[:, 1] = 2.01 + 0.04 * s ** 2  # bulges out towards +y, its normals turned one way
    mesh = _merge(run, fridge)
    cam = np.array([1.0, 0.0, 1.2])
    ends = np.array([[0.05, 2.0, 0.5], [2.45, 2.0, 0.5]])
    off = {}
    for r in (0.0, 3.0):
        p = max(vertical_planes(mesh, cam, PlanesConfig(refit_deg=r), max_tilt=0.3, min_area=0.2), key=lambda q: q.area)
        off[r] = np.abs(ends @ p.n - p.d)
    assert off[3.0].max() < 0.005, off
    assert off[0.0].max() > off[3.0].max(), off


def test_longest_run_hand_computed() -> None:
    from react3d_core.perception.heuristic.planes import _longest_run

    t = np.array([0.0, 0.01, 0.05, 0.09, 0.5, 0.52])  # 4 cm cells 0, 0, 1, 2, 12, 13: runs of 3 and 2 cells
    assert _longest_run(t, 0.04) == pytest.approx(0.12)
    assert _longest_run(np.array([1.0]), 0.04) == pytest.approx(0.04)


def test_fit_direction_leaves_separate_short_pieces_alone() -> None:
    """Two 0.6 m cabinets 0.5 m apart, 1 cm apart in depth, span 1.7 m but no unbroken metre: turning the
    plane would line them up (a sharper density), yet they are two surfaces; the normals' direction stays."""
    from react3d_core.perception.heuristic.planes import fit_direction

    xy = np.concatenate([_line_points(0.0, 0.0, 0.0, 0.6), _line_points(0.0, 0.01, 1.1, 1.7)])
    nd = np.array([1.0, 0.0, 0.0])
    n, _ = fit_direction(xy, np.ones(len(xy)), nd, PlanesConfig(refit_deg=3.0))
    assert n is nd
    n_joined, _ = fit_direction(xy, np.ones(len(xy)), nd, PlanesConfig(refit_deg=3.0, refit_min_extent=0.5))  # it would turn
    assert abs(np.degrees(np.arctan2(n_joined[1], n_joined[0]))) > 0.2


def test_outline_cut_hand_computed() -> None:
    """An L-shaped outline, 200 x 100 px: columns 0-79 covered on all 100 rows, columns 80-199 on rows
    60-99 only. Columns: jump (100 - 40) / 100 = 0.6, between columns 79 and 80 -> cut at 80 (the line
    dropped is on the emptier side). Rows: (200 - 80) / 200 = 0.6 between rows 59 and 60 -> cut at 59.
    An 8-row hole (a handle's scanning shadow) is no corner: the medians over 20 rows ignore it."""
    from react3d_core.perception.heuristic.front_cells import _outline_cut

    cov = np.zeros((100, 200), bool)
    cov[:, :80] = True
    cov[60:, 80:] = True
    assert _outline_cut(cov, 0, 20, np.zeros(200, bool)) == (80, pytest.approx(0.6))
    assert _outline_cut(cov, 1, 20, np.zeros(100, bool)) == (59, pytest.approx(0.6))
    assert _outline_cut(cov, 0, 20, np.arange(200) == 80) == (-1, 0.0)  # a handle on the corner: no cut there
    assert _outline_cut(np.ones((100, 200), bool), 0, 20, np.zeros(200, bool))[1] == 0.0
    holed = np.ones((100, 200), bool)
    holed[40:48, 30:150] = False
    assert _outline_cut(holed, 1, 20, np.zeros(100, bool))[1] == 0.0


def test_tall_unit_beside_a_base_run_splits_at_its_edge() -> None:
    """A tall plain unit (0.5 m x 2 m) beside a 1 m base run of two doors (0.7 m high, a seam between
    them, knob handles) with nothing of the plane above the run: the run's doors come out as cells of
    their own size (without the outline cut, one cell spans the tall unit and the
    first door, and the second door's cell reaches up into the empty wall and is mostly unseen)."""
    res = 0.005
    h, w = 400, 300                                  # 2 m x 1.5 m
    rng = np.random.default_rng(3)
    img = np.full((h, w, 3), 0.8, np.float32) + rng.normal(0, 0.01, (h, w, 3)).astype(np.float32)
    img[:, 100:] = np.array([0.6, 0.7, 0.5], np.float32)  # the run's doors are green; its edge is only a colour step
    img[260:, 199:201] *= 0.8                        # the seam between the two doors
    for c0 in (180, 215):                            # a vertical bar handle beside the seam on each door
        img[280:310, c0:c0 + 4] = 1.6
    cov = np.zeros((h, w), bool)
    cov[:, :100] = True
    cov[260:, 100:] = True                           # the run: 0.7 m high
    o = _ortho(img, res)
    o.n_views[~cov] = 0
    handles = find_handles(o, cov, HeuristicConfig())
    assert len(handles) == 2
    doors = sorted((c for c in split_cells(o, cov, handles, HeuristicConfig()) if c.handles), key=lambda c: c.c0)
    assert len(doors) == 2
    assert [abs(d.r0 - 260) <= 2 for d in doors] == [True, True]
    assert abs(doors[0].c0 - 100) <= 2 and abs(doors[0].c1 - 200) <= 3 and abs(doors[1].c1 - 300) <= 2
    off = HeuristicConfig(cells={"outline_step": 0.0})
    old = sorted((c for c in split_cells(o, cov, handles, off) if c.handles), key=lambda c: c.c0)
    assert any(c.c0 < 90 or c.r0 < 200 for c in old)  # without it a door's cell is not its own


def test_tilted_faces_in_the_slab_cover_a_bevelled_front() -> None:
    """Plane y = 0 facing -y (0.4 x 0.4 m, none of its own faces). 3 cm triangles: turned 20 degrees about z
    (a bevel: within 30 degrees, in the slab), turned 40 degrees (too steep), facing up (a worktop's top),
    facing -y 4 cm behind the plane (a seam's floor, beyond 2.5 cm), facing -y outside the plane's extent,
    and facing +y (the back of a board). Only the bevel paints the coverage, and only with a tilt allowed."""
    def tri(o: list[float], turn_deg: float = 0.0, up: bool = False) -> list[np.ndarray]:
        s, t, p = 0.03, np.radians(turn_deg), np.array(o, float)
        if up:
            return [p, p + [s, 0, 0], p + [0, s, 0]]
        return [p, p + [s * np.cos(t), s * np.sin(t), 0], p + [0, 0, s]]
    tris = [tri([0.1, 0, 0.1], 20), tri([0.2, 0, 0.1], 40), tri([0.1, 0, 0.2], up=True), tri([0.2, 0.04, 0.2]),
            tri([0.6, 0, 0.1]), tri([0.3, 0, 0.3])[::-1]]
    m = TriMesh(np.concatenate(tris), np.arange(3 * len(tris)).reshape(-1, 3))
    o = flat_ortho(np.zeros((100, 100, 3)))
    assert slab_faces(m, o.plane, 0.025, 30.0).tolist() == [0]
    assert slab_faces(m, o.plane, 0.025, 45.0).tolist() == [0, 1]
    assert slab_faces(m, o.plane, 0.05, 30.0).tolist() == [0, 3]
    assert not coverage_from_faces(o, m, 0.0, 0.0).any()  # the plane's own faces: none
    cov = coverage_from_faces(o, m, 0.0, 0.0, 0.025, 30.0)
    c = m.face_centroids[0]
    assert cov.sum() == 1 and cov[int((o.v_top - c[2]) / o.res), int((c[0] - o.u0) / o.res)]


def test_glass_doors_cells_count_their_panes_as_covered() -> None:
    """The two-door run with a 40 x 50 cm pane in each door (no mesh there: the views see the wall behind):
    each door's own surface is its 10 cm frame, 52 % of it, under cells.min_seen. The panes are framed
    holes, so the doors' cells count them as covered and both doors are found; with the panes' coverage
    left out of the cells' test (or no panes) neither is."""
    mesh, frames, images = _seamless_cabinet_scene()
    cen = mesh.face_centroids
    in_pane = np.zeros(mesh.n_faces, bool)
    for x0 in (0.1, 0.7):
        in_pane |= (np.abs(cen[:, 1]) < 1e-6) & (cen[:, 0] > x0) & (cen[:, 0] < x0 + 0.4) & (cen[:, 2] > 0.2) & (cen[:, 2] < 0.7)
    glass = TriMesh(mesh.vertices, mesh.faces[~in_pane], mesh.colors)
    caster = RayCaster(glass)
    rng = np.random.default_rng(1)
    W, H = 480, 360
    images = {f.frame_id: caster.rgb(caster.cast(f.intrinsics.K, f.c2w, W, H), rng) for f in frames}

    def fronts(cfg: HeuristicConfig) -> list:
        res = find_image_fronts(glass, frames, Rasterizer(glass), lambda f: images[f.frame_id], cfg)
        return sorted(res.fronts, key=lambda f: f.center[0])

    found = fronts(HeuristicConfig())
    assert len(found) == 2, [(np.round(f.center, 2), f.w, f.h) for f in found]
    for f, cx in zip(found, (0.3, 0.9)):
        assert abs(f.center[0] - cx) < 0.04
        assert abs(f.w - 0.6) < 0.06 and abs(f.h - 0.7) < 0.05
    assert fronts(HeuristicConfig(image={"pane_cell_cover": False})) == []
    assert fronts(HeuristicConfig(image={"pane_frame": 0.0})) == []
