"""The viewer payload and the HTML report (no browser needed)."""

from __future__ import annotations

import base64
import json
import re

import numpy as np

from react3d_core.data import TriMesh
from react3d_core.viewer import scene_payload, write_report
from react3d_core.viewer.payload import decimate
from react3d_core.viewer.thumbnails import thumbnail


def test_payload_round_trips_arrays(toy_scene):
    p = scene_payload(toy_scene)
    assert [o["id"] for o in p["objects"]] == ["obj_000", "obj_001"]
    part = p["objects"][0]["meshes"]["part"]
    pos = np.frombuffer(base64.b64decode(part["positions"]), np.float32).reshape(-1, 3)
    idx = np.frombuffer(base64.b64decode(part["indices"]), np.uint32).reshape(-1, 3)
    assert pos.shape[0] == part["n_vertices"] and idx.max() < pos.shape[0]
    assert np.allclose(pos.mean(0), [0.75, 1.91, 0.45], atol=1e-3)
    assert p["objects"][1]["joint"]["type"] == "prismatic"


def test_vertex_normals_of_a_flat_square_point_up():
    m = TriMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    assert np.allclose(m.vertex_normals, [[0, 0, 1]] * 4)


def test_decimate_respects_budget(toy_scene):
    from react3d_core.data import load_mesh

    m = load_mesh(toy_scene / "meshes" / "background.ply")
    d = decimate(m, 500)
    assert d.n_faces <= 500 and d.colors.shape == (d.n_vertices, 3)


def test_decimate_keeps_the_surface_and_its_colours():
    # a 1 m x 1 m grid of 20k faces, red left half / blue right half, bent 90 degrees at y = 0.5
    n = 101
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    u, v = u.ravel(), v.ravel()
    pts = np.stack([u, np.minimum(v, 0.5), np.maximum(v - 0.5, 0.0)], 1)
    i = np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]
    i = i.ravel()
    faces = np.concatenate([np.stack([i, i + n, i + 1], 1), np.stack([i + 1, i + n, i + n + 1], 1)])
    cols = np.where((u < 0.5)[:, None], [[255, 0, 0]], [[0, 0, 255]]).astype(np.uint8)
    m = TriMesh(pts, faces, cols)
    d = decimate(m, 2000)
    assert 1500 <= d.n_faces <= 2000
    assert np.allclose(d.bounds(), m.bounds(), atol=1e-3)  # corners survive
    on_plane = np.minimum(np.abs(d.vertices[:, 2]), np.abs(d.vertices[:, 1] - 0.5))
    assert on_plane.max() < 1e-3  # every vertex stays on one of the two planes
    far = np.abs(d.vertices[:, 0] - 0.5) > 0.02
    red = d.vertices[far, 0] < 0.5
    assert (d.colors[far][red] == [255, 0, 0]).all() and (d.colors[far][~red] == [0, 0, 255]).all()


def test_report_is_self_contained(toy_scene, tmp_path):
    out = write_report(toy_scene, tmp_path / "report.html", metrics={"0.25": {"f1": 0.5, "precision": 1.0}})
    html = out.read_text()
    assert "<script src=" not in html and "http://" not in html and "https://" not in html
    payload = json.loads(re.search(r"window.REACT3D_SCENE=(\{.*?\});window.REACT3D_THUMBS", html, re.S).group(1))
    assert len(payload["objects"]) == 2
    assert "obj_001" in html and "Metrics against ground truth" in html and "Timings" in html


def test_thumbnail_crops_around_the_silhouette():
    rgb = np.zeros((100, 200, 3), np.uint8)
    sil = np.zeros((100, 200), bool)
    sil[40:60, 150:170] = True
    t = thumbnail(rgb, sil, size=64)
    assert t.shape[0] <= 64 and t.shape[1] <= 64
    assert t[t.shape[0] // 2, t.shape[1] // 2].tolist() != [0, 0, 0]  # tinted part in the centre
    assert thumbnail(rgb, np.zeros_like(sil)) is None


def test_report_cache_reuses_payload_but_shows_this_runs_timings(toy_scene, tmp_path):
    """A re-convert reads the viewer payload (and thumbnails) back by content; the page still
    carries the current manifest's timings, and a changed mesh is a new entry."""
    import json
    import shutil

    from react3d_core.data import InteractiveScene

    d = tmp_path / "scene"
    shutil.copytree(toy_scene, d)
    cache = tmp_path / "cache"
    first = write_report(d, cache_dir=cache).read_text()
    entries = sorted(cache.rglob("report-*.json"))
    assert len(entries) == 1
    m = InteractiveScene.load(d / "scene.json")
    m.model_copy(update={"timings": {"total": 123.25}}).save(d / "scene.json")
    stamp = entries[0].stat().st_mtime_ns
    second = write_report(d, cache_dir=cache).read_text()
    assert entries[0].stat().st_mtime_ns == stamp and "123.2" in second and second != first
    assert json.loads(entries[0].read_text())["payload"]["background"]
    from react3d_core.data import TriMesh, load_mesh, save_mesh

    bg = load_mesh(d / m.background_mesh)
    save_mesh(d / m.background_mesh, TriMesh(bg.vertices + 0.001, bg.faces, bg.colors))  # new content, new key
    write_report(d, cache_dir=cache)
    assert len(sorted(cache.rglob("report-*.json"))) == 2
