"""A hand-made interactive scene (floor + wall, a cabinet with a revolute door and a drawer)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from react3d_core.data import OBB, Articulation, InteractiveObject, InteractiveScene, TriMesh, save_mesh, save_vertex_ids


def _box(center, extents, color) -> TriMesh:
    m = trimesh.creation.box(extents=extents)
    m = m.subdivide().subdivide()
    return TriMesh(np.asarray(m.vertices) + center, m.faces, np.tile(color, (len(m.vertices), 1)))


def _concat(meshes: list[TriMesh]) -> TriMesh:
    v, f, c, off = [], [], [], 0
    for m in meshes:
        v.append(m.vertices)
        f.append(m.faces + off)
        c.append(m.colors)
        off += m.n_vertices
    return TriMesh(np.concatenate(v), np.concatenate(f), np.concatenate(c))


@pytest.fixture(scope="session")
def toy_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("toy_scene")
    (out / "meshes").mkdir()
    floor = _box([1.0, 1.0, -0.01], [3.0, 3.0, 0.02], [200, 200, 190])
    wall = _box([1.0, 2.5, 1.0], [3.0, 0.05, 2.0], [220, 215, 205])
    carcass = _box([1.0, 2.2, 0.45], [1.0, 0.55, 0.9], [150, 110, 80])
    door = _box([0.75, 1.91, 0.45], [0.48, 0.02, 0.86], [90, 140, 200])
    drawer = _box([1.25, 1.91, 0.7], [0.48, 0.02, 0.36], [200, 90, 80])
    scan = _concat([floor, wall, carcass, door, drawer])
    save_mesh(out / "meshes" / "background.ply", _concat([floor, wall, carcass]))
    save_mesh(out / "scan.ply", scan)
    n0 = floor.n_vertices + wall.n_vertices + carcass.n_vertices
    objs = []
    specs = [
        ("obj_000", door, Articulation(joint_type="revolute", axis=[0, 0, -1], origin=[0.51, 1.91, 0.45], lower=0.0, upper=1.6, limit_source="cap"),
         np.arange(n0, n0 + door.n_vertices)),
        ("obj_001", drawer, Articulation(joint_type="prismatic", axis=[0, -1, 0], origin=[1.25, 1.91, 0.7], lower=0.0, upper=0.4, limit_source="cavity"),
         np.arange(n0 + door.n_vertices, n0 + door.n_vertices + drawer.n_vertices)),
    ]
    for oid, mesh, art, vids in specs:
        d = out / "meshes" / oid
        d.mkdir()
        save_mesh(d / "part.ply", mesh)
        save_vertex_ids(d / "vertex_ids.npz", vids)
        c = mesh.vertices.mean(0)
        ext = np.ptp(mesh.vertices, 0)
        order = np.argsort(-ext)
        axes = np.eye(3)[order]
        if np.linalg.det(axes) < 0:
            axes[2] *= -1
        objs.append(
            InteractiveObject(
                object_id=oid, label="cabinet.door" if art.joint_type == "revolute" else "cabinet.drawer", score=0.9,
                articulation=art, obb=OBB(center=c, axes=axes, extents=ext[order]), front_normal=(0, 1, 0),
                part_mesh=f"meshes/{oid}/part.ply", source_vertex_ids=f"meshes/{oid}/vertex_ids.npz",
                cavity_depth=0.5, cavity_depth_source="hit", top_views=[{"frame_id": "frame_000000", "iou": 0.91}],
            )
        )
    InteractiveScene(scene_id="toy", input_mesh="scan.ply", background_mesh="meshes/background.ply", objects=objs,
                     timings={"fusion": 1.5, "export": 0.7}).save(out / "scene.json")
    return out


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_ARGS = [
    "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-sandbox",
    "--disable-background-networking", "--disable-component-update", "--disable-sync", "--no-first-run",
]


@pytest.fixture(scope="module")
def browser():  # noqa: ANN201 - playwright's Browser; modules using it skip when Chromium is absent
    """Headless Debian Chromium (software GL) for the viewer tests."""
    playwright = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
    if CHROMIUM is None:
        pytest.skip("Debian chromium not installed (apt-get install chromium)")
    with playwright.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()
