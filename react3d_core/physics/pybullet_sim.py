"""PyBullet: the exported URDF with a fixed base and self-collision on (``URDF_USE_SELF_COLLISION``:
every pair of links collides except a child with its parent, PyBullet's default once self-collision is
asked for), inertials from the file, the engine's default solver, gravity -9.81 m/s^2. Pairs of links
that never move (background, carcasses) are switched off: they cannot move anything.

The default velocity motors PyBullet puts on every joint are switched off (force 0); the drive is the
check's PD law applied as joint torques.
"""

from __future__ import annotations

from importlib.metadata import version
from pathlib import Path

import numpy as np

from .sim import PROBE, TOUCH, Contact, Sim, SimJoint, effective_inertia

G = 9.81
DEFAULT_GROUP, ALL_GROUPS = 1, -1
"""Bullet's broad-phase filter of a link with mass (btBroadphaseProxy DefaultFilter, AllFilter)."""


class PybulletSim(Sim):
    engine = "pybullet"

    def __init__(self, urdf: str | Path, timestep: float, contact_breaking: float = 0.002) -> None:
        import pybullet as pb

        self.pb = pb
        self.version = version("pybullet")
        self.cid = cid = pb.connect(pb.DIRECT)
        try:
            pb.setTimeStep(timestep, physicsClientId=cid)
            # Bullet keeps contact points up to this far apart; at its default (0.02 m) a point found where a part
            # slides 5 mm past a neighbour keeps its first normal as it slides, and blocks the part
            pb.setPhysicsEngineParameter(contactBreakingThreshold=float(contact_breaking), physicsClientId=cid)
            pb.setGravity(0, 0, -G, physicsClientId=cid)
            flags = pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_INERTIA_FROM_FILE
            self.body = body = pb.loadURDF(str(urdf), useFixedBase=True, flags=flags, physicsClientId=cid)
        except Exception:
            pb.disconnect(cid)
            raise
        self.dt = float(timestep)
        params = pb.getPhysicsEngineParameters(physicsClientId=cid)
        self.settings = {"file": "URDF", "timestep": self.dt, "fixed_base": True,
                         "self_collision": "on, parent-child pairs excluded (URDF_USE_SELF_COLLISION); pairs of links that never move skipped",
                         "solver_iterations": int(params.get("numSolverIterations", 0)), "gravity": [0, 0, -G],
                         "contact_breaking_threshold": float(contact_breaking),
                         "drive": "PD as joint torques (TORQUE_CONTROL), default motors off"}
        n = pb.getNumJoints(body, physicsClientId=cid)
        infos = [pb.getJointInfo(body, i, physicsClientId=cid) for i in range(n)]
        self.link_names = {-1: pb.getBodyInfo(body, physicsClientId=cid)[0].decode()}
        parent = {}
        for i, info in enumerate(infos):
            self.link_names[i] = info[12].decode()
            parent[i] = int(info[16])
        kinds = {pb.JOINT_REVOLUTE: "revolute", pb.JOINT_PRISMATIC: "prismatic"}
        self.idx = [i for i, info in enumerate(infos) if info[2] in kinds]
        pb.setJointMotorControlArray(body, self.idx, pb.VELOCITY_CONTROL, forces=[0.0] * len(self.idx), physicsClientId=cid)
        for i in self.idx:
            pb.resetJointState(body, i, 0.0, 0.0, physicsClientId=cid)
        self.joints = []
        for i in self.idx:
            info = infos[i]
            st = pb.getLinkState(body, i, computeForwardKinematics=True, physicsClientId=cid)
            R_com = np.asarray(pb.getMatrixFromQuaternion(st[1]), float).reshape(3, 3)
            dyn = pb.getDynamicsInfo(body, i, physicsClientId=cid)
            axis = R_com @ np.asarray(info[13], float)  # Bullet's link frame is the inertial frame
            anchor = np.asarray(st[4], float)
            inertia = R_com @ np.diag(dyn[2]) @ R_com.T
            kind = kinds[info[2]]
            self.joints.append(SimJoint(info[1].decode(), kind, anchor, axis, self.link_names[i], float(info[8]),
                                        float(info[9]), effective_inertia(kind, axis, anchor, float(dyn[0]), np.asarray(st[0]), inertia)))

        def moves(i: int) -> bool:
            while i >= 0:
                if i in self.idx:
                    return True
                i = parent[i]
            return False

        self.moving = frozenset(self.link_names[i] for i in range(n) if moves(i))
        # links that never move cannot push anything: their pairs are skipped, as MuJoCo skips bodies welded
        # to the world (half of each step's cost on a kitchen: the background against every carcass)
        still = [i for i in range(-1, n) if self.link_names[i] not in self.moving]
        for k, a in enumerate(still):
            for b in still[k + 1:]:
                pb.setCollisionFilterPair(body, body, a, b, 0, physicsClientId=cid)
        self.link_index = {self.link_names[i]: i for i in range(n)}
        self.link_parent = {self.link_names[i]: (self.link_names[parent[i]] if parent[i] >= 0 and self.link_names[parent[i]] in self.moving
                                                 else None) for i in range(n) if self.link_names[i] in self.moving}
        self.solid = frozenset(nm for nm in self.moving if pb.getCollisionShapeData(body, self.link_index[nm], physicsClientId=cid))
        self.left_out: frozenset[str] = frozenset()
        self.kp = self.kd = np.zeros(len(self.idx))
        self.fmax = np.inf
        self.probe_id: int | None = None
        self.probe_lift = 0.0

    def set_gains(self, kp: np.ndarray, kd: np.ndarray, fmax: float) -> None:
        self.kp, self.kd, self.fmax = np.asarray(kp, float), np.asarray(kd, float), float(fmax)

    def reset(self, q: np.ndarray) -> None:
        pb, cid = self.pb, self.cid
        if self.probe_id is not None:
            pb.removeBody(self.probe_id, physicsClientId=cid)
            self.probe_id = None
        for i, qi in zip(self.idx, q):
            pb.resetJointState(self.body, i, float(qi), 0.0, physicsClientId=cid)

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        st = self.pb.getJointStates(self.body, self.idx, physicsClientId=self.cid)
        return np.array([s[0] for s in st]), np.array([s[1] for s in st])

    def step(self, q_target: np.ndarray, qd_target: np.ndarray) -> None:
        pb, cid = self.pb, self.cid
        q, qd = self.state()
        f = np.clip(self.kp * (q_target - q) + self.kd * (qd_target - qd), -self.fmax, self.fmax)
        pb.setJointMotorControlArray(self.body, self.idx, pb.TORQUE_CONTROL, forces=f.tolist(), physicsClientId=cid)
        if self.probe_id is not None and self.probe_lift:
            pos = pb.getBasePositionAndOrientation(self.probe_id, physicsClientId=cid)[0]
            pb.applyExternalForce(self.probe_id, -1, [0, 0, self.probe_lift], pos, pb.WORLD_FRAME, physicsClientId=cid)
        pb.stepSimulation(physicsClientId=cid)

    def contacts(self, only: frozenset[str] | None = None) -> list[Contact]:
        pb, cid, names = self.pb, self.cid, self.link_names
        out = []
        if only is None or only - {PROBE}:
            out = [Contact(names[c[3]], names[c[4]], float(c[8]))
                   for c in pb.getContactPoints(bodyA=self.body, bodyB=self.body, physicsClientId=cid) if c[8] <= TOUCH]
            if only is not None:
                out = [c for c in out if c.a in only or c.b in only]
        if self.probe_id is not None:
            out += [Contact(PROBE, names.get(c[4], "?"), float(c[8]))
                    for c in pb.getContactPoints(bodyA=self.probe_id, physicsClientId=cid) if c[8] <= TOUCH]
        return out

    def link_boxes(self) -> dict[str, np.ndarray]:
        pb, cid = self.pb, self.cid
        return {nm: np.asarray(pb.getAABB(self.body, self.link_index[nm], physicsClientId=cid), float) for nm in self.solid}

    def collide_only(self, links: frozenset[str] | None) -> None:
        """A link left out gets collision filter group and mask 0 (it passes no broad phase); back in, the
        group and mask Bullet gives a link with mass (default group, every group)."""
        out = frozenset() if links is None else self.solid - links
        for nm in self.left_out - out:
            self.pb.setCollisionFilterGroupMask(self.body, self.link_index[nm], DEFAULT_GROUP, ALL_GROUPS, physicsClientId=self.cid)
        for nm in out - self.left_out:
            self.pb.setCollisionFilterGroupMask(self.body, self.link_index[nm], 0, 0, physicsClientId=self.cid)
        self.left_out = out

    def add_probe(self, pos: np.ndarray, vel: np.ndarray, radius: float, mass: float, gravity: bool) -> None:
        pb, cid = self.pb, self.cid
        shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=radius, physicsClientId=cid)
        self.probe_id = pb.createMultiBody(mass, shape, basePosition=np.asarray(pos, float).tolist(), physicsClientId=cid)
        pb.resetBaseVelocity(self.probe_id, np.asarray(vel, float).tolist(), [0, 0, 0], physicsClientId=cid)
        self.probe_lift = 0.0 if gravity else mass * G

    def probe(self) -> tuple[np.ndarray, np.ndarray]:
        pb, cid = self.pb, self.cid
        assert self.probe_id is not None
        return (np.asarray(pb.getBasePositionAndOrientation(self.probe_id, physicsClientId=cid)[0], float),
                np.asarray(pb.getBaseVelocity(self.probe_id, physicsClientId=cid)[0], float))

    def close(self) -> None:
        try:
            self.pb.disconnect(self.cid)
        except Exception:  # noqa: BLE001 - already gone
            pass
