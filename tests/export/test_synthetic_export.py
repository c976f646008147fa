"""A synthetic kitchen (scanned-like open part surfaces, many joints) through export, into PyBullet and
MuJoCo: every GT joint moves its part where ``Articulation.move`` predicts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from react3d_core.config.export import ExportConfig
from react3d_core.data import OBB, InteractiveObject, InteractiveScene, load_mesh, save_mesh
from react3d_core.export import export_scene


def scene_from_gt(scan: Path, out: Path, max_objects: int = 6) -> Path:
    """InteractiveScene whose parts are GT parts (with their handles) cut from the scan mesh; no bases."""
    from react3d_core.ground_truth import read_articulate3d

    mesh = load_mesh(scan / "scans" / "mesh_aligned_0.05.ply")
    gt = read_articulate3d(scan / "articulate3d")
    objects, moving = [], []
    for p in gt.movable[:max_objects]:
        faces = [p.tri_indices] + [c.tri_indices for c in gt.parts if c.label.startswith(p.label + ".") and not c.movable]
        f = np.unique(np.concatenate(faces))
        moving.append(f)
        part, _ = mesh.submesh(f)
        oid = f"part_{p.part_id}"
        save_mesh(out / "meshes" / oid / "part.ply", part)
        lo, hi = part.bounds()
        objects.append(
            InteractiveObject(
                object_id=oid, label=p.label, articulation=p.articulation,
                obb=OBB(center=tuple((lo + hi) / 2), axes=((1, 0, 0), (0, 1, 0), (0, 0, 1)), extents=tuple(hi - lo)),
                front_normal=(0, 0, 1), part_mesh=f"meshes/{oid}/part.ply",
            )
        )
    keep = np.setdiff1d(np.arange(mesh.n_faces), np.concatenate(moving))
    save_mesh(out / "meshes" / "background.ply", mesh.submesh(keep)[0])
    scene = InteractiveScene(scene_id="synthetic", input_mesh=str(scan / "scans" / "mesh_aligned_0.05.ply"), background_mesh="meshes/background.ply", objects=objects)
    return scene.save(out / "scene.json")


def test_synthetic_kitchen_exports_and_moves(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    pb = pytest.importorskip("pybullet")
    mujoco = pytest.importorskip("mujoco")
    manifest = scene_from_gt(synthetic_scene(n_frames=2), tmp_path / "scene")
    out = export_scene(manifest, config=ExportConfig(texel_per_m=50, write_glb=False))
    scene = InteractiveScene.load(manifest)
    assert len(scene.objects) >= 3
    cid = pb.connect(pb.DIRECT)
    model = mujoco.MjModel.from_xml_path(str(out["mjcf"]))
    data = mujoco.MjData(model)
    try:
        body = pb.loadURDF(str(out["urdf"]), useFixedBase=True, physicsClientId=cid)
        idx = {pb.getJointInfo(body, i, physicsClientId=cid)[1].decode(): i for i in range(pb.getNumJoints(body, physicsClientId=cid))}
        for obj in scene.objects:
            art = obj.articulation
            pts = load_mesh(manifest.parent / obj.part_mesh).vertices
            local = pts - np.asarray(art.origin)  # the part link sits at the joint origin
            q = 0.5 * art.upper
            j = idx[f"{obj.object_id}_joint"]
            pb.resetJointState(body, j, q, physicsClientId=cid)
            s = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=cid)
            got = local @ Rotation.from_quat(s[5]).as_matrix().T + np.asarray(s[4])
            assert np.linalg.norm(got - art.move(pts, q), axis=1).max() <= 1e-3
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{obj.object_id}_joint")
            data.qpos[:] = 0
            data.qpos[model.jnt_qposadr[jid]] = q
            mujoco.mj_kinematics(model, data)
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, obj.object_id)
            got = local @ data.xmat[b].reshape(3, 3).T + data.xpos[b]
            assert np.linalg.norm(got - art.move(pts, q), axis=1).max() <= 1e-3
    finally:
        pb.disconnect(cid)
    # parts without a base: joints to the world, still one articulation root each, frames consistent
    from pxr import Usd

    from react3d_core.export.usd_checks import check_usd, joint_axis_world

    assert check_usd(out["usd"]) == []
    stage = Usd.Stage.Open(str(out["usd"]))
    for obj in scene.objects:
        _, axis = joint_axis_world(stage, stage.GetPrimAtPath(f"/World/{obj.object_id}/{obj.object_id}_joint"))
        np.testing.assert_allclose(axis, obj.articulation.axis, atol=1e-5)
