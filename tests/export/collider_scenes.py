"""Hand-made scenes whose raw colliders overlap the way scans do, and a small physics driver.

``cabinet_scene``: floor, back wall and a side wall; a scanned cabinet (face frame around the fronts,
a worktop that overhangs them, a shelf inside the door's carcass) around a side-hinged door next to
the side wall and a drawer; carcasses and the drawer box come from ``react3d_core.cavity`` like the
pipeline's. ``angled_carcasses_scene``: two drawers side by side whose fronts turn 6 deg towards each
other, so their 0.45 m deep carcasses overlap at the back. Geometry in metres, z up, the room at y < 0.5.

The driver measures what a robot-learning user meets first: contacts at rest and each joint alone
driven to its upper limit by a position controller with collisions on.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import trimesh

from react3d_core.cavity import PartFrame, base_mesh, inner_box_mesh
from react3d_core.config import CavityConfig
from react3d_core.data import OBB, Articulation, InteractiveObject, InteractiveScene, TriMesh, save_mesh

UP = np.array([0.0, 0.0, 1.0])
GAP = 0.003  # between a front and the frame around it


def _tm(parts: list[trimesh.Trimesh]) -> TriMesh:
    m = trimesh.util.concatenate(parts)
    v = np.asarray(m.vertices)
    rgb = np.clip(np.stack([128 + 90 * np.sin(3 * v[:, 0]), 128 + 90 * np.cos(2 * v[:, 1]), 110 + 60 * v[:, 2]], 1), 0, 255)
    return TriMesh(v, np.asarray(m.faces), rgb.astype(np.uint8))


def box(lo, hi) -> trimesh.Trimesh:  # noqa: ANN001
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(extents=hi_ - lo_).apply_translation((lo_ + hi_) / 2)


def grid(origin, u, v, n: int, m: int | None = None, keep=None) -> trimesh.Trimesh:  # noqa: ANN001
    """An open quad grid origin + [0,1] u + [0,1] v with n x m cells; ``keep(centres) -> bool`` drops cells."""
    m = n if m is None else m
    o, u, v = (np.asarray(x, float) for x in (origin, u, v))
    a, b = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(m) + 0.5) / m, indexing="ij")
    centres = o + a.reshape(-1, 1) * u + b.reshape(-1, 1) * v
    ok = np.ones(len(centres), bool) if keep is None else keep(centres)
    quads = []
    for c in centres[ok]:
        q = [c - u / (2 * n) - v / (2 * m), c + u / (2 * n) - v / (2 * m), c + u / (2 * n) + v / (2 * m), c - u / (2 * n) + v / (2 * m)]
        quads.append(q)
    q = np.asarray(quads).reshape(-1, 3)
    idx = np.arange(len(q)).reshape(-1, 4)
    faces = np.concatenate([idx[:, [0, 1, 2]], idx[:, [0, 2, 3]]])
    return trimesh.Trimesh(q, faces, process=False)


def front_frame(center, u, n, su: float, sv: float, thickness: float = 0.02) -> PartFrame:  # noqa: ANN001
    """The slab frame of a vertical front (``u`` horizontal in-plane, ``n`` into the cavity)."""
    u, n = np.asarray(u, float), np.asarray(n, float)
    return PartFrame(np.asarray(center, float), u, np.cross(n, u), n, su, sv, thickness)


def front_meshes(pf: PartFrame, handle_at: float) -> TriMesh:
    """The front slab and a handle box in front of it at ``handle_at`` x the half width along u."""
    R = np.stack([pf.u, pf.v, pf.n], 1)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, pf.center
    slab = trimesh.creation.box(extents=(pf.su, pf.sv, pf.thickness), transform=T)
    T2 = T.copy()
    T2[:3, 3] = pf.center + handle_at * pf.su / 2 * pf.u - (pf.thickness / 2 + 0.015) * pf.n
    handle = trimesh.creation.box(extents=(0.03, 0.1, 0.03), transform=T2)
    return _tm([slab, handle])


def write_object(out: Path, oid: str, label: str, pf: PartFrame, art: Articulation, depth: float, drawer: bool) -> InteractiveObject:
    cfg = CavityConfig()
    d = out / "meshes" / oid
    save_mesh(d / "part.ply", front_meshes(pf, -0.8 if art.joint_type == "revolute" else 0.0))
    save_mesh(d / "base.ply", base_mesh(pf, depth, cfg))
    inner = None
    if drawer:
        save_mesh(d / "inner.ply", inner_box_mesh(pf, depth, cfg, UP))
        inner = f"meshes/{oid}/inner.ply"
    axes = (tuple(pf.v), tuple(pf.u), tuple(pf.n)) if pf.sv >= pf.su else (tuple(pf.u), tuple(pf.v), tuple(pf.n))
    ext = (max(pf.su, pf.sv), min(pf.su, pf.sv), pf.thickness)
    return InteractiveObject(
        object_id=oid, label=label, articulation=art, obb=OBB(center=tuple(pf.center), axes=axes, extents=ext),
        front_normal=tuple(pf.n), part_mesh=f"meshes/{oid}/part.ply", base_mesh=f"meshes/{oid}/base.ply", inner_mesh=inner,
        cavity_depth=depth,
    )


DOOR_PF = front_frame((-0.75, 0.49, 0.395), (1, 0, 0), (0, 1, 0), 0.48, 0.59)
DRAWER_PF = front_frame((0.30, 0.49, 0.55), (1, 0, 0), (0, 1, 0), 0.58, 0.28)
DOOR = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(-0.99, 0.49, 0.395), lower=0.0, upper=np.pi / 2, limit_source="test")
DRAWER = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0.30, 0.49, 0.55), lower=0.0, upper=0.38, limit_source="test")
DEPTH = 0.46
SHELF_Z = 0.35
WALL_X = -1.0  # the side wall the door's hinge edge stands next to


def _outside(pfs: list[PartFrame], grow: float):  # noqa: ANN202
    def keep(c: np.ndarray) -> np.ndarray:
        ok = np.ones(len(c), bool)
        for pf in pfs:
            r = c - pf.center
            ok &= ~((np.abs(r @ pf.u) <= pf.su / 2 + grow) & (np.abs(r @ pf.v) <= pf.sv / 2 + grow))
        return ok

    return keep


def cabinet_scene(out: Path) -> Path:
    """Write the cabinet scene under ``out``; returns the manifest path."""
    floor = grid((-2, -2, 0), (4, 0, 0), (0, 3, 0), 16, 12)
    back_wall = grid((-2, 1.0, 0), (0, 0, 2.4), (4, 0, 0), 8, 16)
    side_wall = grid((WALL_X, -2, 0), (0, 3, 0), (0, 0, 2.4), 12, 8)
    # the carcass as scanned: a face frame in the fronts' back plane with gaps around the fronts
    frame = grid((-0.98, 0.5, 0.0), (1.58, 0, 0), (0, 0, 0.72), 79, 36, keep=_outside([DOOR_PF, DRAWER_PF], GAP))
    worktop = box((-1.0, 0.46, 0.72), (0.62, 1.0, 0.76))
    side = box((0.6, 0.5, 0.0), (0.62, 1.0, 0.72))
    shelf = grid((-0.97, 0.53, SHELF_Z), (0.44, 0, 0), (0, 0.44, 0), 4)
    save_mesh(out / "meshes" / "background.ply", _tm([floor, back_wall, side_wall, frame, worktop, side, shelf]))
    objects = [write_object(out, "door", "door", DOOR_PF, DOOR, DEPTH, drawer=False),
               write_object(out, "drawer", "drawer", DRAWER_PF, DRAWER, DEPTH, drawer=True)]
    scene = InteractiveScene(scene_id="cabinet", input_mesh="meshes/background.ply", background_mesh="meshes/background.ply", objects=objects)
    return scene.save(out / "scene.json")


def angled_carcasses_scene(out: Path, turn_deg: float = 6.0) -> Path:
    """Two drawers 0.5 m wide side by side (3 mm apart at the front), each front turned ``turn_deg``
    towards the other about z: their carcasses meet behind the gap and overlap at the back. The
    background is the floor alone (a flat scan)."""
    floor = grid((-2, -2, 0), (4, 0, 0), (0, 3, 0), 16, 12)
    save_mesh(out / "meshes" / "background.ply", _tm([floor]))
    objects = []
    for k, sign in enumerate((-1.0, 1.0)):
        t = np.radians(turn_deg) * sign  # the left front's cavity leans right, the right one's left
        u = np.array([np.cos(t), np.sin(t), 0.0])
        n = np.array([-np.sin(t), np.cos(t), 0.0])
        c = np.array([sign * (0.25 + GAP / 2), 0.49, 0.45])
        pf = front_frame(c, u, n, 0.5, 0.3)
        art = Articulation(joint_type="prismatic", axis=tuple(-n), origin=tuple(c), lower=0.0, upper=0.35, limit_source="test")
        objects.append(write_object(out, f"drawer_{k + 1:02d}", "drawer", pf, art, 0.45, drawer=True))
    scene = InteractiveScene(scene_id="angled", input_mesh="meshes/background.ply", background_mesh="meshes/background.ply", objects=objects)
    return scene.save(out / "scene.json")


# ------------------------------------------------------------------ physics driver
SECONDS = 2.0
KP, KD, EFFORT = 400.0, 40.0, 50.0


def urdf_joints(urdf: Path) -> dict[str, tuple[float, float]]:
    out = {}
    for j in ET.parse(urdf).getroot().findall("joint"):
        if j.get("type") in ("revolute", "prismatic"):
            lim = j.find("limit")
            out[j.get("name")] = (float(lim.get("lower")), float(lim.get("upper")))
    return out


def mujoco_drive(mjcf: Path) -> tuple[int, float, dict[str, float]]:
    """(penetrating contacts at rest, deepest penetration at rest, joint -> fraction of its upper limit reached)."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(mjcf))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    dist = np.array([c.dist for c in data.contact[: data.ncon]])
    hinge_slide = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
    jids = [i for i in range(model.njnt) if int(model.jnt_type[i]) in hinge_slide]
    reached = {}
    for jid in jids:
        mujoco.mj_resetData(model, data)
        hi = model.jnt_range[jid][1]
        for _ in range(int(SECONDS / model.opt.timestep)):
            for k in jids:
                qa, da = model.jnt_qposadr[k], model.jnt_dofadr[k]
                target = hi if k == jid else 0.0
                data.qfrc_applied[da] = np.clip(KP * (target - data.qpos[qa]) - KD * data.qvel[da], -EFFORT, EFFORT)
            mujoco.mj_step(model, data)
        reached[mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, jid)] = float(data.qpos[model.jnt_qposadr[jid]] / hi)
    return int((dist < 0).sum()), float(max(0.0, -dist.min())) if len(dist) else 0.0, reached


def pybullet_connect(urdf: Path):  # noqa: ANN201
    import pybullet as pb

    cid = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    flags = pb.URDF_USE_INERTIA_FROM_FILE | pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
    body = pb.loadURDF(str(urdf), useFixedBase=True, flags=flags, physicsClientId=cid)
    names = {pb.getJointInfo(body, i, physicsClientId=cid)[1].decode(): i for i in range(pb.getNumJoints(body, physicsClientId=cid))}
    return pb, cid, body, names


def pybullet_drive(urdf: Path) -> tuple[int, float, dict[str, float]]:
    pb, cid, body, names = pybullet_connect(urdf)
    try:
        pb.performCollisionDetection(physicsClientId=cid)
        d = np.array([c[8] for c in pb.getContactPoints(body, body, physicsClientId=cid)])
        joints = urdf_joints(urdf)
        reached = {}
        for name, (_, hi) in joints.items():
            for other in joints:
                pb.resetJointState(body, names[other], 0.0, physicsClientId=cid)
                pb.setJointMotorControl2(body, names[other], pb.POSITION_CONTROL, targetPosition=hi if other == name else 0.0,
                                         force=EFFORT, positionGain=0.2, velocityGain=1.0, maxVelocity=1.0, physicsClientId=cid)
            for _ in range(int(SECONDS * 240)):
                pb.stepSimulation(physicsClientId=cid)
            reached[name] = pb.getJointState(body, names[name], physicsClientId=cid)[0] / hi
        return int((d < 0).sum()), float(max(0.0, -d.min())) if len(d) else 0.0, reached
    finally:
        pb.disconnect(cid)


def sapien_drive(urdf: Path) -> tuple[int, float, dict[str, float]]:
    import sapien

    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(1 / 240)
    loader = scene.create_urdf_loader()
    builders, _, _ = loader.parse(str(urdf))
    for lb in builders[0].link_builders:
        lb.visual_records = []  # no renderer here: physics only
    builders[0].set_scene(scene)
    art = builders[0].build(fix_root_link=True)
    scene.step()
    sep = np.array([p.separation for c in scene.get_contacts() for p in c.points])
    joints = art.get_active_joints()
    reached = {}
    for idx, j in enumerate(joints):
        art.set_qpos(np.zeros(len(joints)))
        art.set_qvel(np.zeros(len(joints)))
        hi = float(j.limit[0][1])
        for k, jk in enumerate(joints):
            jk.set_drive_property(stiffness=KP, damping=KD, force_limit=EFFORT)
            jk.set_drive_target(hi if k == idx else 0.0)
        for _ in range(int(SECONDS * 240)):
            scene.step()
        reached[j.name] = float(art.get_qpos()[idx] / hi)
    return int((sep < 0).sum()), float(max(0.0, -sep.min())) if len(sep) else 0.0, reached
