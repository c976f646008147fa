"""Texture baking: hand-computed rasterization, gutter filling, texel budget, colour error at vertices."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from react3d_core.config.export import ExportConfig
from react3d_core.data import TriMesh
from react3d_core.texture import (
    bake_texture,
    cell_atlas,
    fill_gutters,
    rasterize_uv,
    sample_bilinear,
    texture_side,
    vertex_color_error,
    write_glb,
    write_obj_folder,
)


def test_texture_side_hand_computed() -> None:
    cfg = ExportConfig(texel_per_m=400, min_texture=64, max_texture=4096)
    # 400 * sqrt(1 / 0.7) = 478.09 -> next multiple of 4 = 480
    assert texture_side(1.0, cfg) == 480
    assert texture_side(1e-6, cfg) == 64
    assert texture_side(1e4, cfg) == 4096


def test_rasterize_one_triangle_hand_computed() -> None:
    px = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]])
    cols = np.array([[[0, 0, 0], [40, 0, 0], [0, 40, 0]]], np.float32)
    img, mask = rasterize_uv(px, np.array([[0, 1, 2]]), cols, 4, 4)
    # texel centres (i+.5, j+.5) inside x + y <= 4  <=>  i + j <= 3: 10 texels
    assert mask.sum() == 10
    assert mask[0, 3] and mask[3, 0] and not mask[3, 1]
    # centre (0.5, 0.5): l1 = l2 = 0.125 -> (5, 5, 0); centre (2.5, 0.5): l1 = .625, l2 = .125 -> (25, 5, 0)
    np.testing.assert_allclose(img[0, 0], [5, 5, 0], atol=1e-5)
    np.testing.assert_allclose(img[0, 2], [25, 5, 0], atol=1e-5)


def test_fill_gutters_grows_charts_and_keeps_covered_texels() -> None:
    img = np.zeros((5, 5, 3), np.float32)
    mask = np.zeros((5, 5), bool)
    img[2, 2] = [90, 30, 60]
    mask[2, 2] = True
    out = fill_gutters(img, mask)
    np.testing.assert_allclose(out[2, 2], [90, 30, 60])
    # a single covered texel floods the whole image with its colour (blur of a constant is constant)
    np.testing.assert_allclose(out, np.broadcast_to([90, 30, 60], out.shape), atol=1e-3)


def test_sample_bilinear_hand_computed() -> None:
    img = np.array([[[0], [100]], [[50], [150]]], np.float32)  # 2x2, row 0 = top
    # uv (0.5, 0.5) is the image centre: mean of the 4 texels = 75
    np.testing.assert_allclose(sample_bilinear(img, np.array([[0.5, 0.5]])), [[75.0]])
    # texel (x=1, y=0) centre: u = 0.75, v = 1 - 0.25 = 0.75
    np.testing.assert_allclose(sample_bilinear(img, np.array([[0.75, 0.75]])), [[100.0]])


def test_cell_atlas_layout() -> None:
    corners, W, H, cols = cell_atlas(5, 3)  # 3 cells -> 2 columns x 2 rows of 3x3 texels
    assert (W, H, cols) == (6, 6, 2)
    np.testing.assert_allclose(corners[0], [[0.5, 0.5], [1.5, 0.5], [0.5, 1.5]])
    np.testing.assert_allclose(corners[3], [[5.5, 2.5], [4.5, 2.5], [5.5, 1.5]])
    np.testing.assert_allclose(corners[4], [[0.5, 3.5], [1.5, 3.5], [0.5, 4.5]])


def _sphere(random_colors: bool) -> TriMesh:
    m = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    v = m.vertices
    if random_colors:
        col = np.random.default_rng(0).integers(0, 256, (len(v), 3))
    else:
        col = (v + 0.5) * 200 + 20
    return TriMesh(v, m.faces, np.asarray(col, np.uint8))


@pytest.mark.parametrize("method", ["xatlas", "cells"])
def test_baked_texture_reproduces_vertex_colours(method: str) -> None:
    mesh = _sphere(random_colors=False)
    tm = bake_texture(mesh, ExportConfig(texel_per_m=200), method=method)
    assert tm.method == method
    assert len(tm.faces) == mesh.n_faces
    np.testing.assert_allclose(tm.vertices, mesh.vertices[tm.source_vertex])
    assert vertex_color_error(tm, mesh) <= 3.0


def test_cell_atlas_is_exact_for_arbitrary_colours() -> None:
    mesh = _sphere(random_colors=True)
    tm = bake_texture(mesh, ExportConfig(texel_per_m=100), method="cells")
    assert vertex_color_error(tm, mesh) <= 0.5


def test_xatlas_error_with_random_colours_is_bounded() -> None:
    mesh = _sphere(random_colors=True)
    tm = bake_texture(mesh, ExportConfig(texel_per_m=400), method="xatlas")
    assert vertex_color_error(tm, mesh) <= 3.0


def test_written_obj_and_glb_read_back(tmp_path) -> None:  # noqa: ANN001
    mesh = _sphere(random_colors=False)
    tm = bake_texture(mesh, method="cells")
    obj = write_obj_folder(tm, tmp_path / "link", offset=np.array([1.0, 0, 0]))
    assert sorted(p.name for p in obj.parent.iterdir()) == ["material.mtl", "material_0.png", "mesh.obj"]
    back = trimesh.load(obj, process=False, force="mesh")
    assert len(back.faces) == mesh.n_faces
    np.testing.assert_allclose(back.bounds[0][0], -0.5 - 1.0, atol=0.02)
    glb = write_glb(tm, tmp_path / "link.glb")
    assert trimesh.load(glb, force="mesh").faces.shape[0] == mesh.n_faces
