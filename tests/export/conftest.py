"""A hand-made interactive scene: floor + wall background, a cabinet with a revolute door and a
cabinet with a drawer (front + inner box), vertex-coloured, written with react3d_core.data.

Geometry (metres, z up, the room is at y < 0.5, cabinets stand against the wall at y = 1; the
background also holds the door cabinet's scanned top at z = 0.61):
- door cabinet x in [-1, -0.5], drawer cabinet x in [0, 0.6]; both open at y = 0.5;
- door: a scanned-like open sheet at y = 0.48 with a handle box, hinge at x = -0.99, axis -z
  (q > 0 swings it out into the room), limits [0, pi/2];
- drawer: front plate y in [0.47, 0.49] with an inner box of 5 walls behind it, axis -y
  (q > 0 pulls it out), limits [0, 0.4].
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from react3d_core.config.export import ExportConfig
from react3d_core.data import OBB, Articulation, InteractiveObject, InteractiveScene, TriMesh, save_mesh
from tests.physics.scenes import box, open_box


def colour(v: np.ndarray) -> np.ndarray:
    """Smooth vertex colours from position (so baked textures can be checked)."""
    rgb = np.stack([128 + 100 * np.sin(3 * v[:, 0]), 128 + 100 * np.cos(2 * v[:, 1]), 100 + 60 * v[:, 2]], 1)
    return np.clip(np.round(rgb), 0, 255).astype(np.uint8)


def _mesh(parts: list[trimesh.Trimesh]) -> TriMesh:
    m = trimesh.util.concatenate(parts)
    return TriMesh(m.vertices, m.faces, colour(np.asarray(m.vertices)))


def grid(origin: np.ndarray, u: np.ndarray, v: np.ndarray, n: int) -> trimesh.Trimesh:
    """An open n x n quad grid spanning origin + [0,1] u + [0,1] v."""
    s = np.linspace(0, 1, n + 1)
    a, b = np.meshgrid(s, s, indexing="ij")
    verts = origin + a.reshape(-1, 1) * u + b.reshape(-1, 1) * v
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    return trimesh.Trimesh(verts, faces, process=False)


DOOR = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(-0.99, 0.48, 0.32), lower=0.0, upper=np.pi / 2, limit_source="test")
DRAWER = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0.3, 0.48, 0.17), lower=0.0, upper=0.4, limit_source="test")
INNER_LO, INNER_HI = (0.04, 0.49, 0.06), (0.56, 0.95, 0.26)


def build_scene(out: Path) -> Path:
    """Write the test scene under ``out``; returns the manifest path."""
    meshes = out / "meshes"
    floor = grid(np.array([-2.0, -2.0, 0.0]), np.array([4.0, 0, 0]), np.array([0, 3.0, 0]), 12)
    wall = grid(np.array([-2.0, 1.0, 0.0]), np.array([0, 0, 2.5]), np.array([4.0, 0, 0]), 8)
    # the scan also holds the door cabinet's top, inside its carcass: no longer a collider once the carcass stands there
    top = grid(np.array([-0.98, 0.52, 0.61]), np.array([0.46, 0, 0]), np.array([0, 0.46, 0]), 2)
    save_mesh(meshes / "background.ply", _mesh([floor, wall, top]))

    door_sheet = grid(np.array([-0.99, 0.48, 0.03]), np.array([0.48, 0, 0]), np.array([0, 0, 0.58]), 6)
    handle = box((-0.6, 0.45, 0.30), (-0.56, 0.47, 0.40))
    save_mesh(meshes / "door" / "part.ply", _mesh([door_sheet, handle]))
    save_mesh(meshes / "door" / "base.ply", _mesh(open_box((-1.0, 0.5, 0.02), (-0.5, 1.0, 0.62), 0.02, "-y")))

    save_mesh(meshes / "drawer" / "part.ply", _mesh([box((0.01, 0.47, 0.03), (0.59, 0.49, 0.31))]))
    save_mesh(meshes / "drawer" / "inner.ply", _mesh(open_box(INNER_LO, INNER_HI, 0.01, "+z")))
    save_mesh(meshes / "drawer" / "base.ply", _mesh(open_box((0.0, 0.5, 0.02), (0.6, 1.0, 0.32), 0.02, "-y")))

    ex = ((1, 0, 0), (0, 0, 1), (0, 1, 0))
    objects = [
        InteractiveObject(
            object_id="door", label="cabinet door", articulation=DOOR,
            obb=OBB(center=(-0.75, 0.48, 0.32), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.58, 0.48, 0.02)),
            front_normal=(0, 1, 0), part_mesh="meshes/door/part.ply", base_mesh="meshes/door/base.ply", cavity_depth=0.5,
        ),
        InteractiveObject(
            object_id="drawer", label="drawer", articulation=DRAWER,
            obb=OBB(center=(0.3, 0.48, 0.17), axes=ex, extents=(0.58, 0.28, 0.02)),
            front_normal=(0, 1, 0), part_mesh="meshes/drawer/part.ply", base_mesh="meshes/drawer/base.ply",
            inner_mesh="meshes/drawer/inner.ply", cavity_depth=0.5,
        ),
    ]
    scene = InteractiveScene(scene_id="test_room", input_mesh="meshes/background.ply", background_mesh="meshes/background.ply", objects=objects)
    return scene.save(out / "scene.json")


FAST = ExportConfig(texel_per_m=100, write_glb=True)


@pytest.fixture(scope="session")
def scene_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("scene")
    build_scene(d)
    return d


@pytest.fixture(scope="session")
def exported(tmp_path_factory: pytest.TempPathFactory, scene_dir: Path) -> dict[str, Path]:
    """The test scene exported once to all formats (read-only for tests)."""
    from react3d_core.export import export_scene

    d = tmp_path_factory.mktemp("exported") / "scene"
    shutil.copytree(scene_dir, d)
    return export_scene(d / "scene.json", config=FAST.model_copy(update={"ros_package": True}))
