"""Shared foundation pieces: camera conversions (hand-computed), Intrinsics, and the rasterizer vs projection."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.camera import (
    c2w_to_colmap, c2w_to_nerfstudio_scannetpp, colmap_to_c2w, invert, look_at, nerfstudio_scannetpp_to_c2w,
    opencv_to_opengl_c2w, opengl_to_opencv_c2w, project, quat_to_rot, unproject,
)
from react3d_core.data.frames import Intrinsics, validate_pose
from react3d_core.data.mesh import TriMesh
from react3d_core.raster.rasterizer import Rasterizer


def test_project_hand_computed() -> None:
    K = np.array([[100.0, 0, 50], [0, 200.0, 40], [0, 0, 1]])
    uv, z = project(np.array([[0.2, -0.1, 2.0]]), K, np.eye(4))
    # u = 100 * 0.2/2 + 50 = 60; v = 200 * -0.1/2 + 40 = 30
    assert uv[0] == pytest.approx([60.0, 30.0]) and z[0] == 2.0
    d = np.zeros((80, 100)); d[30, 60] = 2.0
    assert unproject(d, K, np.eye(4))[30, 60] == pytest.approx([0.2, -0.1, 2.0])


def test_quaternion_and_colmap() -> None:
    s = np.sqrt(0.5)
    # 90 deg about z: x -> y
    assert quat_to_rot([s, 0, 0, s]) @ [1, 0, 0] == pytest.approx([0, 1, 0])
    c2w = colmap_to_c2w(np.array([s, 0, 0, s]), np.array([1.0, 0, 0]))
    # w2c = [Rz90 | (1,0,0)]; camera centre = -R^T t = -(Rz-90 (1,0,0)) = (0, 1, 0)
    assert c2w[:3, 3] == pytest.approx([0, 1, 0])
    q, t = c2w_to_colmap(c2w)
    assert q == pytest.approx([s, 0, 0, s]) and t == pytest.approx([1, 0, 0])


def test_gl_cv_and_scannetpp_nerfstudio() -> None:
    T = look_at(np.array([1.0, -2.0, 1.5]), np.array([0.0, 0.0, 0.5]))
    gl = opencv_to_opengl_c2w(T)
    assert gl[:3, 2] == pytest.approx(-T[:3, 2]) and gl[:3, 0] == pytest.approx(T[:3, 0])
    assert opengl_to_opencv_c2w(gl) == pytest.approx(T)
    ns = c2w_to_nerfstudio_scannetpp(T)
    validate_pose(ns)
    # translation: rows x,y swapped, z negated
    assert ns[:3, 3] == pytest.approx([-2.0, 1.0, -1.5])
    assert nerfstudio_scannetpp_to_c2w(ns) == pytest.approx(T)
    assert invert(T) @ T == pytest.approx(np.eye(4))


def test_intrinsics_scaled_and_validation() -> None:
    k = Intrinsics(fx=1500, fy=1400, cx=960, cy=720, width=1920, height=1440).scaled(256, 192)
    assert (k.fx, k.fy, k.cx, k.cy) == pytest.approx((200.0, 1400 * 192 / 1440, 128.0, 96.0))
    with pytest.raises(ValueError, match="positive"):
        Intrinsics(fx=0, fy=1, cx=1, cy=1, width=2, height=2)
    with pytest.raises(ValueError, match="finite"):
        Intrinsics(fx=np.nan, fy=1, cx=1, cy=1, width=2, height=2)


def _grid_mesh(n: int = 24) -> TriMesh:
    """A wavy height field (x, y in [-1, 1], z = 0.15 sin) seen from above: self-occlusion is small but real."""
    xs = np.linspace(-1, 1, n + 1)
    X, Y = np.meshgrid(xs, xs)
    Z = 0.15 * np.sin(3 * X) * np.cos(2 * Y)
    V = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    a, b, c, d = i, i + 1, i + n + 1, i + n + 2
    F = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return TriMesh(V, F)


@pytest.mark.parametrize("size", [(160, 120), (96, 72)])
def test_raster_face_ids_match_centroid_projection(size: tuple[int, int]) -> None:
    mesh = _grid_mesh()
    base = Intrinsics(fx=150, fy=150, cx=95.0, cy=50.0, width=160, height=120)  # off-centre principal point
    K = base.scaled(*size)
    c2w = look_at(np.array([0.3, -1.2, 2.2]), np.array([0.0, 0.0, 0.0]))
    res = Rasterizer(mesh).render(K.K, c2w, K.width, K.height)
    cent = mesh.vertices[mesh.faces].mean(1)
    uv, z = project(cent, K.K, invert(c2w))
    px = np.round(uv).astype(int)
    inside = (z > 0) & (px[:, 0] >= 0) & (px[:, 0] < K.width) & (px[:, 1] >= 0) & (px[:, 1] < K.height)
    idx = np.nonzero(inside)[0]
    # visible = centroid depth agrees with the depth buffer at its pixel
    dbuf = res.depth[px[idx, 1], px[idx, 0]]
    vis = idx[np.abs(dbuf - z[idx]) < 0.01]
    assert len(vis) > 200
    agree = res.face_ids[px[vis, 1], px[vis, 0]] == vis
    assert agree.mean() >= 0.99, agree.mean()
    # an off-by-principal-point render (cx mirrored) would not agree: the test can fail
    Kbad = K.K.copy(); Kbad[0, 2] = K.width - K.cx
    bad = Rasterizer(mesh).render(Kbad, c2w, K.width, K.height)
    assert (bad.face_ids[px[vis, 1], px[vis, 0]] == vis).mean() < 0.5


def test_rasterizer_cast_rays_closest_points_and_distance_hand_computed() -> None:
    # unit square in z = 0 (two faces, normal +z); rays shaped (2, 2, 3) keep their leading axes
    mesh = TriMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    r = Rasterizer(mesh)
    o = np.array([[[0.75, 0.25, 2.0], [0.25, 0.75, 2.0]], [[0.5, 0.5, -1.0], [3.0, 3.0, 1.0]]])
    d = np.array([[[0, 0, -1.0], [0, 0, -2.0]], [[0, 0, 1.0], [0, 0, -1.0]]])
    h = r.cast_rays(o, d)
    assert h.t.shape == (2, 2) and h.uvs.shape == (2, 2, 2) and h.normals.shape == (2, 2, 3)
    # t is in units of the direction's length: 2 m down a unit ray, 1 step of a 2 m one
    assert np.allclose(h.t[0], [2.0, 1.0]) and h.t[1, 0] == pytest.approx(1.0) and np.isinf(h.t[1, 1])
    assert h.face_ids.tolist() == [[0, 1], [h.face_ids[1, 0], -1]] and h.face_ids[1, 0] in (0, 1)
    assert np.allclose(h.normals[0], [[0, 0, 1], [0, 0, 1]])
    # (0.75, 0.25) in face (0, 1, 2): barycentric weights 0.25, 0.5, 0.25 -> uv of corners 1 and 2
    assert np.allclose(h.uvs[0, 0], [0.5, 0.25])
    t, ids = r.first_hit(o[0], d[0])
    assert np.allclose(t, [2.0, 1.0]) and ids.tolist() == [0, 1]
    p = np.array([[0.25, 0.75, 0.3], [2.0, 0.5, 0.0]])
    cp, face, _ = r.closest_points(p)
    assert np.allclose(cp, [[0.25, 0.75, 0.0], [1.0, 0.5, 0.0]]) and face[0] == 1
    assert np.allclose(r.distance(p), [0.3, 1.0])
