"""The export loads and moves correctly in PyBullet, MuJoCo, yourdfpy and usd-core."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from react3d_core.data import InteractiveScene, load_mesh


JOINTS = {"door": "door_joint", "drawer": "drawer_joint"}


def half_limit(art) -> float:  # noqa: ANN001
    return 0.5 * (art.upper if art.upper > 0 else art.lower)


def scene_of(exported: dict[str, Path]) -> tuple[InteractiveScene, Path]:
    root = exported["urdf"].parents[2]
    return InteractiveScene.load(root / "scene.json"), root


def urdf_visual_obj(urdf: Path, link: str) -> Path:
    node = ET.parse(urdf).getroot().find(f"link[@name='{link}']/visual/geometry/mesh")
    return urdf.parent / node.get("filename")  # type: ignore[union-attr, operator]


def local_vertices(obj: Path) -> np.ndarray:
    return np.asarray(trimesh.load(obj, process=False, force="mesh").vertices)


# ---------------------------------------------------------------- PyBullet
def pybullet_body(urdf: Path):  # noqa: ANN201
    pb = pytest.importorskip("pybullet")
    cid = pb.connect(pb.DIRECT)
    body = pb.loadURDF(str(urdf), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=cid)
    names = {pb.getJointInfo(body, i, physicsClientId=cid)[1].decode(): i for i in range(pb.getNumJoints(body, physicsClientId=cid))}
    return pb, cid, body, names


def pb_pose(pb, cid, body, j: int) -> np.ndarray:  # noqa: ANN001
    s = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=cid)
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(s[5]).as_matrix()
    T[:3, 3] = s[4]
    return T


def apply(T: np.ndarray, v: np.ndarray) -> np.ndarray:
    return v @ T[:3, :3].T + T[:3, 3]


def test_pybullet_joint_motion_matches_articulation(exported: dict[str, Path]) -> None:
    scene, root = scene_of(exported)
    pb, cid, body, names = pybullet_body(exported["urdf"])
    try:
        for obj in scene.objects:
            j = names[JOINTS[obj.object_id]]
            info = pb.getJointInfo(body, j, physicsClientId=cid)
            assert (info[8], info[9]) == pytest.approx((obj.articulation.lower, obj.articulation.upper))
            local = local_vertices(urdf_visual_obj(exported["urdf"], obj.object_id))
            pb.resetJointState(body, j, 0.0, physicsClientId=cid)
            closed = apply(pb_pose(pb, cid, body, j), local)
            # at q = 0 the exported part sits exactly on the scanned part
            scanned = load_mesh(root / obj.part_mesh).vertices
            assert cKDTree(scanned).query(closed)[0].max() <= 1e-6
            q = half_limit(obj.articulation)
            pb.resetJointState(body, j, q, physicsClientId=cid)
            moved = apply(pb_pose(pb, cid, body, j), local)
            err = np.linalg.norm(moved - obj.articulation.move(closed, q), axis=1).max()
            assert err <= 1e-3, (obj.object_id, err)
            assert np.linalg.norm(moved - closed, axis=1).max() > 0.05  # it really moved
            pb.resetJointState(body, j, 0.0, physicsClientId=cid)
    finally:
        pb.disconnect(cid)


def test_pybullet_gravity_rollout_keeps_closed_parts_still(exported: dict[str, Path]) -> None:
    scene, _ = scene_of(exported)
    pb, cid, body, names = pybullet_body(exported["urdf"])
    try:
        pb.setGravity(0, 0, -9.81, physicsClientId=cid)
        for j in names.values():  # no motor: only damping and contacts act
            pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0, physicsClientId=cid)
        parts = {o.object_id: names[JOINTS[o.object_id]] for o in scene.objects}
        start = {k: pb_pose(pb, cid, body, j) for k, j in parts.items()}
        for _ in range(480):  # 2 s at 240 Hz
            pb.stepSimulation(physicsClientId=cid)
        for k, j in parts.items():
            T = pb_pose(pb, cid, body, j)
            assert np.all(np.isfinite(T))
            local = local_vertices(urdf_visual_obj(exported["urdf"], k))
            disp = np.linalg.norm(apply(T, local) - apply(start[k], local), axis=1).max()
            assert disp <= 0.01, (k, disp)
    finally:
        pb.disconnect(cid)


INNER_LO, INNER_HI = (0.04, 0.49, 0.06), (0.56, 0.95, 0.26)  # the drawer's inner box (tests/export/conftest.py)


def inside_inner_box(p: np.ndarray, shift: np.ndarray) -> bool:
    lo = np.asarray(INNER_LO) + shift
    hi = np.asarray(INNER_HI) + shift
    return bool(np.all(p > lo) and np.all(p < hi))


def test_pybullet_ball_rests_inside_open_drawer(exported: dict[str, Path]) -> None:
    pb, cid, body, names = pybullet_body(exported["urdf"])
    try:
        pb.setGravity(0, 0, -9.81, physicsClientId=cid)
        j = names["drawer_joint"]
        pb.resetJointState(body, j, 0.3, physicsClientId=cid)
        pb.setJointMotorControl2(body, j, pb.POSITION_CONTROL, targetPosition=0.3, force=500, physicsClientId=cid)
        shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.03, physicsClientId=cid)
        ball = pb.createMultiBody(0.1, shape, basePosition=[0.3, 0.35, 0.45], physicsClientId=cid)
        for _ in range(480):
            pb.stepSimulation(physicsClientId=cid)
        pos = np.array(pb.getBasePositionAndOrientation(ball, physicsClientId=cid)[0])
        vel = np.linalg.norm(pb.getBaseVelocity(ball, physicsClientId=cid)[0])
        assert inside_inner_box(pos, np.array([0, -0.3, 0])), pos
        assert pos[2] < 0.06 + 0.01 + 0.03 + 0.01  # on the inner bottom, not on top of a hull
        assert vel < 0.05
    finally:
        pb.disconnect(cid)


def test_yourdfpy_fk_agrees_with_pybullet(exported: dict[str, Path]) -> None:
    yourdfpy = pytest.importorskip("yourdfpy")
    scene, _ = scene_of(exported)
    robot = yourdfpy.URDF.load(str(exported["urdf"]), load_meshes=False, build_scene_graph=True)
    pb, cid, body, names = pybullet_body(exported["urdf"])
    try:
        cfg = {JOINTS[o.object_id]: half_limit(o.articulation) for o in scene.objects}
        robot.update_cfg(cfg)
        for name, q in cfg.items():
            pb.resetJointState(body, names[name], q, physicsClientId=cid)
        for o in scene.objects:
            T_y = robot.get_transform(frame_to=o.object_id, frame_from="world")
            T_p = pb_pose(pb, cid, body, names[JOINTS[o.object_id]])
            np.testing.assert_allclose(T_y, T_p, atol=1e-6)
    finally:
        pb.disconnect(cid)


# ---------------------------------------------------------------- MuJoCo
def mj_part_pose(mujoco, model, data, name: str) -> np.ndarray:  # noqa: ANN001
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    T = np.eye(4)
    T[:3, :3] = data.xmat[b].reshape(3, 3)
    T[:3, 3] = data.xpos[b]
    return T


def mjcf_obj(mjcf: Path, link: str) -> Path:
    return mjcf.parents[1] / "assets" / link / "visual_0" / "mesh.obj"


def test_mujoco_compiles_and_moves_parts(exported: dict[str, Path]) -> None:
    mujoco = pytest.importorskip("mujoco")
    scene, root = scene_of(exported)
    model = mujoco.MjModel.from_xml_path(str(exported["mjcf"]))
    data = mujoco.MjData(model)
    for obj in scene.objects:
        art = obj.articulation
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, JOINTS[obj.object_id])
        assert jid >= 0
        np.testing.assert_allclose(model.jnt_range[jid], [art.lower, art.upper])
        assert model.jnt_type[jid] == (mujoco.mjtJoint.mjJNT_HINGE if art.joint_type == "revolute" else mujoco.mjtJoint.mjJNT_SLIDE)
        local = local_vertices(mjcf_obj(exported["mjcf"], obj.object_id))
        data.qpos[:] = 0
        mujoco.mj_kinematics(model, data)
        closed = apply(mj_part_pose(mujoco, model, data, obj.object_id), local)
        assert cKDTree(load_mesh(root / obj.part_mesh).vertices).query(closed)[0].max() <= 1e-6
        q = half_limit(art)
        data.qpos[model.jnt_qposadr[jid]] = q
        mujoco.mj_kinematics(model, data)
        moved = apply(mj_part_pose(mujoco, model, data, obj.object_id), local)
        assert np.linalg.norm(moved - art.move(closed, q), axis=1).max() <= 1e-3
    # the URDF carries the <mujoco> compiler block, so MuJoCo imports it too
    urdf_model = mujoco.MjModel.from_xml_path(str(exported["urdf"]))
    assert urdf_model.njnt == model.njnt


def test_mujoco_rollout_and_ball_in_drawer(exported: dict[str, Path], tmp_path: Path) -> None:
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(exported["mjcf"]))
    data = mujoco.MjData(model)
    names = list(JOINTS)
    mujoco.mj_forward(model, data)
    start = {n: mj_part_pose(mujoco, model, data, n) for n in names}
    for _ in range(1000):  # 2 s
        mujoco.mj_step(model, data)
    for n in names:
        T = mj_part_pose(mujoco, model, data, n)
        assert np.all(np.isfinite(T))
        local = local_vertices(mjcf_obj(exported["mjcf"], n))
        assert np.linalg.norm(apply(T, local) - apply(start[n], local), axis=1).max() <= 0.01

    # ball: same folder so relative mesh paths resolve
    text = exported["mjcf"].read_text().replace(
        "</worldbody>",
        '<body name="ball" pos="0.3 0.35 0.45"><freejoint/><inertial pos="0 0 0" mass="0.1" diaginertia="3.6e-5 3.6e-5 3.6e-5"/>'
        '<geom type="sphere" size="0.03"/></body></worldbody>',
    )
    ball_xml = exported["mjcf"].parent / "ball_test.xml"
    ball_xml.write_text(text)
    try:
        model = mujoco.MjModel.from_xml_path(str(ball_xml))
    finally:
        ball_xml.unlink()
    data = mujoco.MjData(model)
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "drawer_joint")
    data.qpos[model.jnt_qposadr[jid]] = 0.3
    for _ in range(1000):
        mujoco.mj_step(model, data)
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "ball")
    q = float(data.qpos[model.jnt_qposadr[jid]])
    pos = data.xpos[b].copy()
    assert inside_inner_box(pos, np.array([0, -q, 0])), (pos, q)
    assert pos[2] < 0.06 + 0.01 + 0.03 + 0.01
