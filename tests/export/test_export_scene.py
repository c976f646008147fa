"""export_scene end to end: manifest bookkeeping, round trip through the URDF importer, movable
output folder, ROS package, the ``react3d export`` command and bad input."""

from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from react3d_core.data import InteractiveScene
from react3d_core.errors import InputError
from react3d_core.config.export import ExportConfig
from react3d_core.export import export_scene, import_urdf

FAST = ExportConfig(texel_per_m=100, write_glb=False)


def test_manifest_records_exports(exported: dict[str, Path]) -> None:
    root = exported["urdf"].parents[2]
    scene = InteractiveScene.load(root / "scene.json")
    assert scene.exports == {"urdf": "export/urdf/scene.urdf", "usd": "export/usd/scene.usda", "mjcf": "export/mjcf/scene.xml"}
    for fmt, rel in scene.exports.items():
        assert (root / rel) == exported[fmt] and exported[fmt].is_file()
    urdf_dir = exported["urdf"].parent
    assets = root / "export" / "assets"
    assert (urdf_dir / "display.launch.py").is_file() and (urdf_dir / "display.launch").is_file()
    assert (assets / "drawer" / "visual_0.glb").is_file()
    # one folder per visual: trimesh's fixed MTL/PNG names never collide
    for link in ("background", "door_base", "door", "drawer_base", "drawer"):
        assert (assets / link / "visual_0" / "material_0.png").is_file()
    # every mesh and texture is written once, in the shared assets: the format folders hold none
    for fmt in ("urdf", "mjcf", "usd"):
        own = [p for p in (root / "export" / fmt).rglob("*") if p.is_file() and "ros" not in p.parts]
        assert not [p for p in own if p.suffix in (".obj", ".png", ".jpg", ".glb")], fmt
    assert (root / "export" / "usd" / "scene.usdc").is_file()
    sizes = scene.export_sizes
    assert set(sizes) == {"assets", "urdf", "usd", "mjcf", "total"}
    assert sizes["total"] >= sizes["assets"] + sizes["usd"] + sizes["mjcf"] and sizes["assets"] > 0


def test_usd_root_is_small_and_sublayers_the_binary_stage(exported: dict[str, Path]) -> None:
    from pxr import Sdf, Usd, UsdGeom

    root = Sdf.Layer.FindOrOpen(str(exported["usd"]))
    assert list(root.subLayerPaths) == ["./scene.usdc"] and root.GetFileFormat().formatId == "usda"
    assert exported["usd"].stat().st_size < 2000
    assert Sdf.Layer.FindOrOpen(str(exported["usd"].with_suffix(".usdc"))).GetFileFormat().formatId == "usdc"
    stage = Usd.Stage.Open(str(exported["usd"]))
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetDefaultPrim().GetPath() == "/World"


def test_round_trip_urdf_to_articulations(exported: dict[str, Path]) -> None:
    scene = InteractiveScene.load(exported["urdf"].parents[2] / "scene.json")
    back = import_urdf(exported["urdf"])
    assert set(back) == {o.object_id for o in scene.objects}
    for obj in scene.objects:
        a, b = obj.articulation, back[obj.object_id]
        assert a.joint_type == b.joint_type
        np.testing.assert_allclose(b.axis, a.axis, atol=1e-12)
        np.testing.assert_allclose(b.origin, a.origin, atol=1e-12)
        assert (b.lower, b.upper) == (a.lower, a.upper)
        pts = np.random.default_rng(0).normal(size=(20, 3))
        q = 0.5 * a.upper
        np.testing.assert_allclose(b.move(pts, q), a.move(pts, q), atol=1e-12)


def test_moved_export_folder_still_loads(exported: dict[str, Path], tmp_path: Path) -> None:
    pb = pytest.importorskip("pybullet")
    mujoco = pytest.importorskip("mujoco")
    yourdfpy = pytest.importorskip("yourdfpy")
    from react3d_core.export.usd_checks import check_usd

    moved = tmp_path / "elsewhere" / "export"
    shutil.copytree(exported["urdf"].parents[1], moved)
    urdf = moved / "urdf" / "scene.urdf"
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(urdf), useFixedBase=True, physicsClientId=cid)
        shapes = [pb.getCollisionShapeData(body, j, physicsClientId=cid) for j in range(pb.getNumJoints(body, physicsClientId=cid))]
        assert all(len(s) > 0 for s in shapes)
        files = [sh[4] for s in shapes for sh in s if sh[2] == pb.GEOM_MESH]  # background patches are boxes, no files
        assert files and all(str(moved).encode() in f for f in files)
    finally:
        pb.disconnect(cid)
    model = mujoco.MjModel.from_xml_path(str(moved / "mjcf" / "scene.xml"))
    assert model.njnt == 2 and model.ntex >= 5
    robot = yourdfpy.URDF.load(str(urdf), load_meshes=True)
    assert len(robot.scene.geometry) >= 6
    assert check_usd(moved / "usd" / "scene.usda") == []


def test_ros_package_uses_package_paths(exported: dict[str, Path]) -> None:
    pkg = exported["urdf"].parent / "ros" / "test_room_description"
    assert (pkg / "package.xml").is_file() and (pkg / "CMakeLists.txt").is_file()
    root = ET.parse(pkg / "urdf" / "scene.urdf").getroot()
    names = [m.get("filename") for m in root.iter("mesh")]
    assert names and all(n.startswith("package://test_room_description/meshes/") for n in names)
    for n in names:
        assert (pkg / n[len("package://test_room_description/") :]).is_file()


def test_export_command_reexports_selected_formats(scene_dir: Path, tmp_path: Path) -> None:
    from flows.cli import main

    d = tmp_path / "scene"
    shutil.copytree(scene_dir, d)
    assert main(["export", str(d), "--formats", "mjcf,urdf", "--texel-per-m", "50"]) == 0
    assert (d / "export" / "mjcf" / "scene.xml").is_file() and (d / "export" / "urdf" / "scene.urdf").is_file()
    assert not (d / "export" / "usd").exists()
    assert set(json.loads((d / "scene.json").read_text())["exports"]) == {"urdf", "mjcf"}
    assert main(["export", str(d), "--formats", "obj"]) == 2
    assert main(["export", str(tmp_path / "missing")]) == 2


def test_bad_limits_are_one_line_input_errors(scene_dir: Path, tmp_path: Path) -> None:
    d = tmp_path / "scene"
    shutil.copytree(scene_dir, d)
    data = json.loads((d / "scene.json").read_text())
    data["objects"][0]["articulation"]["lower"] = 0.2
    (d / "scene.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match="lower <= 0 <= upper"):
        export_scene(d / "scene.json", formats=("urdf",))
    with pytest.raises(InputError, match="unknown export format"):
        export_scene(d / "scene.json", formats=("fbx",))
    (d / "meshes" / "door" / "part.ply").write_bytes(b"ply\nformat ascii 1.0\nend_header\n")
    data["objects"][0]["articulation"]["lower"] = 0.0
    (d / "scene.json").write_text(json.dumps(data))
    with pytest.raises(InputError):
        export_scene(d / "scene.json", formats=("urdf",))
    assert not (d / "export" / "urdf").exists()  # nothing half-written


def test_cell_atlas_path_loads_in_simulators(scene_dir: Path, tmp_path: Path) -> None:
    """Large scans take the per-triangle atlas (OBJ with shared positions and per-corner UVs)."""
    pb = pytest.importorskip("pybullet")
    mujoco = pytest.importorskip("mujoco")
    from react3d_core.config.export import ExportConfig

    d = tmp_path / "scene"
    shutil.copytree(scene_dir, d)
    out = export_scene(d, formats=("urdf", "mjcf"), config=ExportConfig(xatlas_max_faces=1, texel_per_m=50, write_glb=False))
    obj = out["urdf"].parents[1] / "assets" / "background" / "visual_0" / "mesh.obj"
    text = obj.read_text()
    assert text.count("\nv ") == 13 * 13 + 9 * 9 + 3 * 3 and " 1/" in text  # scan positions once (floor, wall, cabinet top), UVs per corner
    model = mujoco.MjModel.from_xml_path(str(out["mjcf"]))
    assert model.ntex >= 5
    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(str(out["urdf"]), useFixedBase=True, physicsClientId=cid)
        assert pb.getNumJoints(body, physicsClientId=cid) == 5
    finally:
        pb.disconnect(cid)


def test_collisions_are_cached_by_content_and_reused_by_a_reexport(scene_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A second export (other formats, through the CLI) reads the decompositions back: the cached files
    are not rewritten, and pieces come back identical. A changed mesh gets a new entry."""
    from flows.cli import main

    from react3d_core.export.collision import cached_pieces, convex_pieces

    cache = tmp_path / "cache"
    monkeypatch.setenv("REACT3D_CACHE", str(cache))
    d = tmp_path / "scene"
    shutil.copytree(scene_dir, d)
    export_scene(d, formats=("urdf",), config=FAST)
    entries = sorted((cache / "collisions").rglob("*.npz"))
    assert len(entries) == 1 + 2 + 3  # background patches; door base, part; drawer base, part, inner
    stamps = {p: p.stat().st_mtime_ns for p in entries}
    assert main(["export", str(d), "--formats", "mjcf,usd"]) == 0
    assert sorted((cache / "collisions").rglob("*.npz")) == entries
    assert {p: p.stat().st_mtime_ns for p in entries} == stamps  # read, not recomputed
    from react3d_core.data import load_mesh

    mesh = load_mesh(d / "meshes" / "drawer" / "inner.ply")
    fresh = convex_pieces(mesh, 8, FAST.min_collision_thickness)
    back = cached_pieces(cache / "collisions", "convex", mesh, (8, FAST.min_collision_thickness), lambda: [])
    assert len(back) == len(fresh) and all(np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces) for a, b in zip(back, fresh))
    moved = mesh.__class__(mesh.vertices + 0.01, mesh.faces, mesh.colors)
    assert cached_pieces(cache / "collisions", "convex", moved, (8, FAST.min_collision_thickness), lambda: []) == []


def test_jpeg_textures_load_in_all_simulators(scene_dir: Path, tmp_path: Path) -> None:
    """texture_format=jpg: URDF/USD read the JPEG, MuJoCo (PNG only) gets a PNG copy beside it."""
    pb = pytest.importorskip("pybullet")
    mujoco = pytest.importorskip("mujoco")
    from react3d_core.config.export import ExportConfig
    from react3d_core.export.usd_checks import check_usd

    d = tmp_path / "scene"
    shutil.copytree(scene_dir, d)
    out = export_scene(d, config=ExportConfig(texel_per_m=100, texture_format="jpg", write_glb=False))
    tex = d / "export" / "assets" / "door" / "visual_0"
    assert (tex / "material_0.jpg").is_file() and (tex / "material_0.png").is_file()
    assert "map_Kd material_0.jpg" in (tex / "material.mtl").read_text()
    assert mujoco.MjModel.from_xml_path(str(out["mjcf"])).ntex >= 5
    cid = pb.connect(pb.DIRECT)
    try:
        assert pb.getNumJoints(pb.loadURDF(str(out["urdf"]), useFixedBase=True, physicsClientId=cid), physicsClientId=cid) == 5
    finally:
        pb.disconnect(cid)
    assert check_usd(out["usd"]) == []
