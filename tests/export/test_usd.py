"""USD export: opens, validates, joint frames agree and match the articulation, textures bound."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from react3d_core.data import InteractiveScene
from react3d_core.export.usd import align_x
from react3d_core.export.usd_checks import check_usd, joint_axis_world, usd_validation_errors

pxr = pytest.importorskip("pxr")


@pytest.mark.parametrize("axis", [(1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, -1, 0), (0.3, -0.4, 0.866), (-1, 1e-12, 0)])
def test_align_x_maps_x_onto_axis(axis: tuple[float, float, float]) -> None:
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    R = align_x(a)
    np.testing.assert_allclose(R @ [1, 0, 0], a, atol=1e-9)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_usd_stage_passes_validation_and_our_checks(exported: dict[str, Path]) -> None:
    from pxr import Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.Open(str(exported["usd"]))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert UsdPhysics.GetStageKilogramsPerUnit(stage) == 1.0
    assert usd_validation_errors(stage) == []
    assert check_usd(exported["usd"]) == []
    roots = [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.ArticulationRootAPI)]
    assert sorted(str(p.GetPath()) for p in roots) == ["/World/door", "/World/drawer"]
    # no subdivision on scanned meshes
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert meshes and all(m.GetSubdivisionSchemeAttr().Get() == "none" for m in meshes)


def test_usd_joint_world_axis_and_limits_match_articulation(exported: dict[str, Path]) -> None:
    from pxr import Usd, UsdPhysics

    scene = InteractiveScene.load(exported["urdf"].parents[2] / "scene.json")
    stage = Usd.Stage.Open(str(exported["usd"]))
    for obj in scene.objects:
        prim = stage.GetPrimAtPath(f"/World/{obj.object_id}/{obj.object_id}_joint")
        art = obj.articulation
        origin, axis = joint_axis_world(stage, prim)
        np.testing.assert_allclose(axis, art.axis, atol=1e-5)
        if art.joint_type == "revolute":  # the origin matters only on the hinge line
            d = origin - np.asarray(art.origin)
            assert np.linalg.norm(d - np.dot(d, art.axis) * np.asarray(art.axis)) <= 1e-5
            lim = UsdPhysics.RevoluteJoint(prim)
            scale = 180 / np.pi
        else:
            lim = UsdPhysics.PrismaticJoint(prim)
            scale = 1.0
        assert lim.GetLowerLimitAttr().Get() == pytest.approx(art.lower * scale, abs=1e-4)
        assert lim.GetUpperLimitAttr().Get() == pytest.approx(art.upper * scale, abs=1e-4)


def test_check_usd_catches_misaligned_frames_and_triangle_colliders(exported: dict[str, Path], tmp_path: Path) -> None:
    from pxr import Gf, Usd, UsdPhysics

    d = tmp_path / "usd"
    shutil.copytree(exported["usd"].parent, d)
    stage = Usd.Stage.Open(str(d / "scene.usda"))
    UsdPhysics.Joint(stage.GetPrimAtPath("/World/door/door_joint")).GetLocalPos1Attr().Set(Gf.Vec3f(0.1, 0, 0))
    piece = stage.GetPrimAtPath("/World/drawer/drawer/collisions/piece_0")
    UsdPhysics.MeshCollisionAPI(piece).GetApproximationAttr().Set("none")
    UsdPhysics.MassAPI(stage.GetPrimAtPath("/World/drawer/drawer")).GetMassAttr().Set(0.0)
    stage.GetRootLayer().Save()
    problems = check_usd(d / "scene.usda")
    assert any("frame origins differ" in p for p in problems)
    assert any("triangle-mesh collider" in p for p in problems)
    assert any("mass 0.0" in p for p in problems)


def test_usd_visuals_keep_scan_topology_with_face_varying_uvs(exported: dict[str, Path], scene_dir: Path) -> None:
    from pxr import Usd, UsdGeom

    from react3d_core.data import load_mesh

    stage = Usd.Stage.Open(str(exported["usd"]))
    scan = load_mesh(scene_dir / "meshes" / "background.ply")
    # the scan is written once, split into the faces that collide and those in a part's path or a carcass
    prims = [stage.GetPrimAtPath(f"/World/background/background_visual_0{s}") for s in ("", "_visual_only")]
    assert all(p.IsValid() for p in prims)
    corners, n_points = [], 0
    for prim in prims:
        mesh = UsdGeom.Mesh(prim)
        points = np.asarray(mesh.GetPointsAttr().Get())
        idx = np.asarray(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 3)
        assert len(np.unique(idx)) == len(points)  # shared points (scan topology), none unused
        st = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st")
        assert st.GetInterpolation() == UsdGeom.Tokens.faceVarying
        assert len(st.Get()) == idx.size
        corners.append(points[idx])
        n_points += len(points)
    assert n_points <= scan.n_vertices + 200  # only vertices on the cut between the two are written twice
    tri = np.concatenate(corners)
    assert len(tri) == scan.n_faces
    # same triangles as the scan (as point sets)
    np.testing.assert_allclose(np.sort(tri.sum(1), axis=0), np.sort(scan.vertices[scan.faces].sum(1), axis=0), atol=1e-5)


def test_usd_convex_colliders_sit_on_their_own_centre_and_in_place(exported: dict[str, Path]) -> None:
    """Each convex collider's points are centred on 0 and its prim is moved into place (PhysX cooks a hull
    in its own coordinates and loses a small one far from its origin); in the world, the drawer's pieces
    span its front and box."""
    from pxr import Usd, UsdGeom

    from react3d_core.data import load_mesh

    stage = Usd.Stage.Open(str(exported["usd"]))
    pieces = [p for p in stage.Traverse() if "/collisions/piece_" in str(p.GetPath())]
    assert pieces
    drawer: list[np.ndarray] = []
    for prim in pieces:
        points = np.asarray(UsdGeom.Mesh(prim).GetPointsAttr().Get(), float)
        np.testing.assert_allclose((points.min(0) + points.max(0)) / 2, 0, atol=1e-6)
        if str(prim.GetPath()).startswith("/World/drawer/drawer/"):
            M = np.asarray(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
            drawer.append(points @ M[:3, :3] + M[3, :3])  # USD matrices act on row vectors
    scene = InteractiveScene.load(exported["usd"].parents[2] / "scene.json")
    obj = next(o for o in scene.objects if o.object_id == "drawer")
    root = exported["usd"].parents[2]
    verts = np.concatenate([load_mesh(root / rel).vertices for rel in (obj.part_mesh, obj.inner_mesh) if rel])
    world = np.concatenate(drawer)
    lo, hi = verts.min(0), verts.max(0)
    assert np.all(world.min(0) >= lo - 0.006) and np.all(world.max(0) <= hi + 0.006)
    assert np.all(world.min(0) <= lo + 0.01) and np.all(world.max(0) >= hi - 0.01)
