"""SAPIEN 3 (PhysX 5 on the CPU, the engine of ManiSkill): the exported URDF, root link fixed, visual
records dropped before building (the loader needs a renderer for visual shapes; physics does not).

PhysX articulations never collide a link with its parent; every other pair collides. Each convex
collision file becomes one convex shape. The drive is PhysX's joint drive in force mode with the
check's stiffness and damping (plus the URDF's joint damping, which SAPIEN also puts in the drive) and
force limit. Enhanced determinism is on, so a rerun gives the same numbers.

Joint friction is the URDF's ``<dynamics friction>`` (0 in our exports). SAPIEN 3's builder reads it but
never applies it, so every joint it loads keeps PhysX's default coefficient 0.05, which resists in
proportion to the force the hinge carries: a 19 cm oven door (0.5 kg) driven by the check's gains stopped
at 84 % of its 11 degree limit, with nothing touching it. Users driving our URDFs in SAPIEN should set
``joint.set_friction(0)`` (or the value they want) after loading.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from .sim import PROBE, TOUCH, Contact, Sim, SimJoint, effective_inertia

STILL_BIT = 1 << 31
"""Ignore-group bit (collision group 2) that links that never move share during an episode."""

ACTIVE = {"revolute": "revolute", "revolute_unwrapped": "revolute", "prismatic": "prismatic"}


def import_sapien():  # noqa: ANN201
    """SAPIEN without its libvulkan warning (no renderer is used)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import sapien
    return sapien


class SapienSim(Sim):
    engine = "sapien"

    def __init__(self, urdf: str | Path, timestep: float) -> None:
        sapien = self.sapien = import_sapien()
        self.version = sapien.__version__
        physx = sapien.physx
        before = physx.get_scene_config()
        physx.set_scene_config(gravity=np.array([0, 0, -9.81], np.float32), enable_enhanced_determinism=True)
        try:
            self.scene = scene = sapien.Scene([physx.PhysxCpuSystem()])
        finally:
            physx.set_scene_config(before)
        scene.set_timestep(timestep)
        self.dt = float(timestep)
        loader = scene.create_urdf_loader()
        loader.fix_root_link = True
        builders, actors, _ = loader.parse(str(urdf))
        friction = {}
        for b in builders:
            for lb in b.link_builders:
                lb.visual_records = []
                friction[lb.joint_record.name] = float(lb.joint_record.friction)
        for a in actors:
            a.visual_records = []
        arts = [b.build() for b in builders]
        for a in actors:  # a link no joint reaches: part of the fixed scene
            a.build_static()
        if not arts:
            raise ValueError(f"{urdf}: no articulation (no movable joint) in the URDF")
        self.arts = arts
        shape, body = physx.get_shape_config(), physx.get_body_config()
        self.settings = {"file": "URDF, visuals dropped", "timestep": self.dt, "fixed_root": True, "device": "cpu",
                         "contact_offset": float(shape.contact_offset), "rest_offset": float(shape.rest_offset),
                         "solver_position_iterations": int(body.solver_position_iterations),
                         "solver_velocity_iterations": int(body.solver_velocity_iterations),
                         "self_collision": "on, parent-child pairs excluded (PhysX articulation)",
                         "enhanced_determinism": True, "drive": "PhysX joint drive, force mode",
                         "joint_friction": "the URDF's <dynamics friction> (SAPIEN's loader leaves PhysX's 0.05)"}
        self.active = [(a, j) for a in arts for j in a.active_joints]
        for _, j in self.active:  # SAPIEN's builder reads <dynamics friction> but never applies it
            j.set_friction(friction.get(j.name, 0.0))
        for a in arts:
            a.set_qpos(np.zeros(a.dof))
        self.damping0 = np.array([float(j.damping) for _, j in self.active])
        self.joints = []
        for _, j in self.active:
            T = j.get_global_pose().to_transformation_matrix()
            link = j.child_link
            com = (link.pose * link.cmass_local_pose).to_transformation_matrix()
            inertia = com[:3, :3] @ np.diag(np.asarray(link.inertia, float)) @ com[:3, :3].T
            kind = ACTIVE[j.type]
            lo, hi = np.asarray(j.limit, float).reshape(-1, 2)[0]
            self.joints.append(SimJoint(j.name, kind, T[:3, 3].copy(), T[:3, 0].copy(), link.name, float(lo), float(hi),
                                        effective_inertia(kind, T[:3, 0], T[:3, 3], float(link.mass), com[:3, 3], inertia)))

        def moves(link) -> bool:  # noqa: ANN001
            while link is not None:
                if link.joint is not None and link.joint.type in ACTIVE:
                    return True
                link = link.parent
            return False

        self.moving = frozenset(link.name for a in arts for link in a.links if moves(link))
        self.links = {link.name: link for a in arts for link in a.links}
        self.link_parent = {n: (link.parent.name if link.parent is not None and link.parent.name in self.moving else None)
                            for n, link in self.links.items() if n in self.moving}
        self.groups0 = {n: [list(sh.get_collision_groups()) for sh in link.collision_shapes] for n, link in self.links.items()}
        self.probe_entity = None
        self.probe_body = None

    def set_gains(self, kp: np.ndarray, kd: np.ndarray, fmax: float) -> None:
        for (_, j), p, d, d0 in zip(self.active, kp, kd, self.damping0):
            j.set_drive_properties(float(p), float(d + d0), force_limit=float(fmax), mode="force")

    def reset(self, q: np.ndarray) -> None:
        if self.probe_entity is not None:
            self.scene.remove_entity(self.probe_entity)
            self.probe_entity = self.probe_body = None
        k = 0
        for a in self.arts:
            a.set_qpos(np.asarray(q[k:k + a.dof], np.float32))
            a.set_qvel(np.zeros(a.dof, np.float32))
            a.set_qf(np.zeros(a.dof, np.float32))
            k += a.dof
        for (_, j), qi in zip(self.active, q):
            j.set_drive_target(float(qi))
            j.set_drive_velocity_target(0.0)

    def step(self, q_target: np.ndarray, qd_target: np.ndarray) -> None:
        for (_, j), qt, vt in zip(self.active, q_target, qd_target):
            j.set_drive_target(float(qt))
            j.set_drive_velocity_target(float(vt))
        self.scene.step()

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        q = np.concatenate([np.asarray(a.qpos, float) for a in self.arts])
        qd = np.concatenate([np.asarray(a.qvel, float) for a in self.arts])
        return q, qd

    def contacts(self, only: frozenset[str] | None = None) -> list[Contact]:
        out = []
        for c in self.scene.get_contacts():
            a, b = (body.entity.name for body in c.bodies)  # the probe's entity is named PROBE
            if only is not None and a not in only and b not in only:
                continue
            for p in c.points:
                if p.separation <= TOUCH:
                    out.append(Contact(a, b, float(p.separation)))
        return out

    def link_boxes(self) -> dict[str, np.ndarray]:
        return {n: np.asarray(self.links[n].compute_global_aabb_tight(), float) for n in self.moving
                if self.links[n].collision_shapes}

    def collide_only(self, links: frozenset[str] | None) -> None:
        """Also, outside ``None``, links that never move skip each other (the ignore group of PhysX's filter:
        their contacts cannot move anything, and an episode reads only the driven link's or the probe's)."""
        for n, link in self.links.items():
            for sh, g in zip(link.collision_shapes, self.groups0[n]):
                if links is None:
                    new = g
                elif n in self.moving:
                    new = g if n in links else [0, 0, 0, 0]
                else:
                    new = [g[0], g[1], g[2] | STILL_BIT, g[3]]
                if list(sh.get_collision_groups()) != new:
                    sh.set_collision_groups(new)

    def add_probe(self, pos: np.ndarray, vel: np.ndarray, radius: float, mass: float, gravity: bool) -> None:
        sapien = self.sapien
        builder = self.scene.create_actor_builder()
        builder.add_sphere_collision(radius=radius, density=mass / (4 / 3 * np.pi * radius ** 3))
        builder.set_initial_pose(sapien.Pose(np.asarray(pos, np.float32)))
        ent = builder.build(name=PROBE)
        body = ent.find_component_by_type(sapien.physx.PhysxRigidDynamicComponent)
        body.set_linear_velocity(np.asarray(vel, np.float32))
        body.set_disable_gravity(not gravity)
        self.probe_entity, self.probe_body = ent, body

    def probe(self) -> tuple[np.ndarray, np.ndarray]:
        b = self.probe_body
        return np.asarray(b.pose.p, float), np.asarray(b.linear_velocity, float)

    def close(self) -> None:
        self.arts = []
        self.active = []
        self.scene = None  # type: ignore[assignment]
