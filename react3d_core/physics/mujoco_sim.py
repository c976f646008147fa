"""MuJoCo: the exported MJCF as written (its time step, gravity, contact settings, collision filters).

Loaded through ``MjSpec`` with one extra body appended to the world: the probe sphere (a free joint,
parked 1 km below the scene, out of reach of every collider, until a probe episode places it), so one compiled model
serves every episode. Bodies of the scene keep their ids and joint addresses.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .sim import PROBE, TOUCH, Contact, Sim, SimJoint, effective_inertia

PARK = np.array([0.0, 0.0, -1000.0])
ALL_BITS = (1 << 31) - 1


class MujocoSim(Sim):
    engine = "mujoco"

    def __init__(self, mjcf: str | Path) -> None:
        import mujoco

        self.mj = mujoco
        self.version = mujoco.__version__
        spec = mujoco.MjSpec.from_file(str(mjcf))
        # compiled with gravity compensation: MuJoCo applies ``body_gravcomp`` only when some body had it at
        # compile time (``ngravcomp``); set at run time alone it is ignored and a "compensated" probe falls
        body = spec.worldbody.add_body(name=PROBE, mass=0.1, inertia=[4e-5] * 3, ipos=[0, 0, 0], explicitinertial=True, gravcomp=1.0)
        free = body.add_freejoint(name=f"{PROBE}_free")
        free.damping, free.armature, free.frictionloss = [0.0] * 3, 0.0, 0.0  # not the file's joint defaults
        geom = body.add_geom(name=PROBE, type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.03, 0, 0])
        geom.contype, geom.conaffinity = ALL_BITS, ALL_BITS  # collides with every geom that collides with anything
        m = self.m = spec.compile()
        d = self.d = mujoco.MjData(m)
        self.dt = float(m.opt.timestep)
        self.settings = {"file": "as written", "timestep": self.dt, "gravity": m.opt.gravity.tolist(),
                         "integrator": int(m.opt.integrator), "cone": int(m.opt.cone),
                         "drive": "PD as qfrc_applied"}
        self.body_names = [m.body(i).name or f"body_{i}" for i in range(m.nbody)]
        self.geom_names = [m.geom(i).name or f"geom_{i}" for i in range(m.ngeom)]
        self.body_id = {n: i for i, n in enumerate(self.body_names)}
        self.pbody = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, PROBE)
        self.pgeom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, PROBE)
        pj = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{PROBE}_free")
        self.p_qadr, self.p_vadr = int(m.jnt_qposadr[pj]), int(m.jnt_dofadr[pj])
        hinge, slide = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
        ids = [j for j in range(m.njnt) if int(m.jnt_type[j]) in (hinge, slide)]
        d.qpos[:] = m.qpos0
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        self.qadr = np.array([m.jnt_qposadr[j] for j in ids], int)
        self.vadr = np.array([m.jnt_dofadr[j] for j in ids], int)
        self.joints = []
        for j in ids:
            b = int(m.jnt_bodyid[j])
            kind = "revolute" if int(m.jnt_type[j]) == hinge else "prismatic"
            lo, hi = (m.jnt_range[j] if m.jnt_limited[j] else (-np.inf, np.inf))
            R = d.ximat[b].reshape(3, 3)
            inertia = R @ np.diag(m.body_inertia[b]) @ R.T
            axis, anchor = d.xaxis[j].copy(), d.xanchor[j].copy()
            self.joints.append(SimJoint(m.joint(j).name, kind, anchor, axis, self.body_names[b], float(lo), float(hi),
                                        effective_inertia(kind, axis, anchor, float(m.body_mass[b]), d.xipos[b], inertia)))
        self.moving = frozenset(self.body_names[b] for b in range(m.nbody) if m.body_weldid[b] != 0 and b != self.pbody)
        self.link_parent = {self.body_names[b]: (self.body_names[int(m.body_parentid[b])] if m.body_weldid[int(m.body_parentid[b])] != 0
                                                 else None) for b in range(m.nbody) if self.body_names[b] in self.moving}
        self.contype0, self.conaffinity0 = m.geom_contype.copy(), m.geom_conaffinity.copy()
        self.body_contype0, self.body_conaffinity0 = m.body_contype.copy(), m.body_conaffinity.copy()
        self.kp = self.kd = np.zeros(len(self.joints))
        self.fmax = np.inf

    def set_gains(self, kp: np.ndarray, kd: np.ndarray, fmax: float) -> None:
        self.kp, self.kd, self.fmax = np.asarray(kp, float), np.asarray(kd, float), float(fmax)

    def reset(self, q: np.ndarray) -> None:
        m, d, mj = self.m, self.d, self.mj
        mj.mj_resetData(m, d)
        d.qpos[self.qadr] = q
        m.body_gravcomp[self.pbody] = 1.0  # parked: it stays where it is
        self._place_probe(PARK, np.zeros(3))
        mj.mj_forward(m, d)

    def _place_probe(self, pos: np.ndarray, vel: np.ndarray) -> None:
        d = self.d
        d.qpos[self.p_qadr:self.p_qadr + 7] = [*pos, 1, 0, 0, 0]
        d.qvel[self.p_vadr:self.p_vadr + 6] = [*vel, 0, 0, 0]

    def step(self, q_target: np.ndarray, qd_target: np.ndarray) -> None:
        d = self.d
        q, qd = d.qpos[self.qadr], d.qvel[self.vadr]
        f = np.clip(self.kp * (q_target - q) + self.kd * (qd_target - qd), -self.fmax, self.fmax)
        d.qfrc_applied[:] = 0
        d.qfrc_applied[self.vadr] = f
        self.mj.mj_step(self.m, d)

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.d.qpos[self.qadr].copy(), self.d.qvel[self.vadr].copy()

    def contacts(self, only: frozenset[str] | None = None) -> list[Contact]:
        d, m = self.d, self.m
        n = d.ncon
        if n == 0:
            return []
        c = d.contact
        dist = np.asarray(c.dist[:n])
        ok = dist <= TOUCH
        if only is not None:
            ids = [self.body_id[x] for x in only if x in self.body_id]
            ok &= np.isin(m.geom_bodyid[np.asarray(c.geom[:n])], ids).any(1)
        keep = np.flatnonzero(ok)
        g = np.asarray(c.geom[:n])[keep]
        b = m.geom_bodyid[g]
        bn, gn = self.body_names, self.geom_names
        return [Contact(bn[b0], bn[b1], float(dist[k]), gn[g0], gn[g1])
                for k, (b0, b1), (g0, g1) in zip(keep, b, g)]

    def link_boxes(self) -> dict[str, np.ndarray]:
        m, d = self.m, self.d
        out: dict[str, np.ndarray] = {}
        g = np.flatnonzero((self.contype0 | self.conaffinity0) != 0)
        for k in g:
            name = self.body_names[int(m.geom_bodyid[k])]
            if name not in self.moving:
                continue
            R = d.geom_xmat[k].reshape(3, 3)
            c = d.geom_xpos[k] + R @ m.geom_aabb[k, :3]  # the geom's box: centre offset and half sizes in its frame
            h = np.abs(R) @ m.geom_aabb[k, 3:]
            box = np.array([c - h, c + h])
            out[name] = box if name not in out else np.array([np.minimum(out[name][0], box[0]), np.maximum(out[name][1], box[1])])
        return out

    def collide_only(self, links: frozenset[str] | None) -> None:
        """The bits of the geoms and of their bodies (the broad phase reads the bodies' OR of their geoms'
        bits, which ``mj_setConst`` recomputes from the geoms as they are)."""
        m = self.m
        m.geom_contype[:], m.geom_conaffinity[:] = self.contype0, self.conaffinity0
        m.body_contype[:], m.body_conaffinity[:] = self.body_contype0, self.body_conaffinity0
        if links is None:
            return
        off = [self.body_id[n] for n in self.moving - links]
        g = np.isin(m.geom_bodyid, off)
        m.geom_contype[g], m.geom_conaffinity[g] = 0, 0
        m.body_contype[off], m.body_conaffinity[off] = 0, 0

    def add_probe(self, pos: np.ndarray, vel: np.ndarray, radius: float, mass: float, gravity: bool) -> None:
        m, d, mj = self.m, self.d, self.mj
        g, b = self.pgeom, self.pbody
        if (m.geom_size[g, 0], m.body_mass[b]) != (radius, mass):
            m.geom_size[g, 0] = radius
            m.geom_rbound[g] = radius
            m.geom_aabb[g] = [0, 0, 0, radius, radius, radius]
            m.body_mass[b] = mass
            m.body_inertia[b] = 0.4 * mass * radius ** 2
            qpos, qvel = d.qpos.copy(), d.qvel.copy()
            mj.mj_setConst(m, d)  # the constraint solver's per-body weights follow the new mass and inertia
            d.qpos[:], d.qvel[:] = qpos, qvel
        m.body_gravcomp[b] = 0.0 if gravity else 1.0
        self._place_probe(np.asarray(pos, float), np.asarray(vel, float))
        mj.mj_forward(m, d)

    def probe(self) -> tuple[np.ndarray, np.ndarray]:
        d = self.d
        return d.qpos[self.p_qadr:self.p_qadr + 3].copy(), d.qvel[self.p_vadr:self.p_vadr + 3].copy()
