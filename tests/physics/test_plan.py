"""The check's geometry and control, hand-computed: fronts and cavities from the manifest, probe
placement and verdict rules, joint matching, the PD gains and the target trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.physics import PhysicsConfig
from react3d_core.data import OBB, Articulation, InteractiveObject
from react3d_core.physics import drive
from react3d_core.physics.result import EngineCheck, JointCheck, ProbeCheck
from react3d_core.physics.sim import Contact, SimJoint, effective_inertia
from react3d_core.physics.targets import (CavityBox, JointPose, advance, cavity_box, cavity_probe, fell_enough,
                                          front_of, front_probe, match_joints, probe_radius)

from tests.physics.scenes import DOOR, DRAWER

DOOR_OBJ = InteractiveObject(
    object_id="door", articulation=DOOR, obb=OBB(center=(-0.75, 0.48, 0.32), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)),
                                                 extents=(0.58, 0.48, 0.02)),
    front_normal=(0, 1, 0), part_mesh="p.ply", cavity_depth=0.48)
DRAWER_OBJ = InteractiveObject(
    object_id="drawer", articulation=DRAWER, obb=OBB(center=(0.3, 0.48, 0.17), axes=((1, 0, 0), (0, 0, 1), (0, 1, 0)),
                                                     extents=(0.58, 0.28, 0.02)),
    front_normal=(0, 1, 0), part_mesh="p.ply", inner_mesh="i.ply", cavity_depth=0.48)


def test_front_takes_its_thickness_along_the_front_normal() -> None:
    f = front_of(DOOR_OBJ)
    assert f.thickness == pytest.approx(0.02) and {f.su, f.sv} == {0.58, 0.48}
    np.testing.assert_allclose(f.outer, [-0.75, 0.47, 0.32])
    np.testing.assert_allclose(f.back, [-0.75, 0.49, 0.32])
    assert not f.moving_cavity and front_of(DRAWER_OBJ).moving_cavity
    assert f.goal == pytest.approx(np.pi / 2)


def test_door_cavity_probe_is_dropped_at_the_cavity_centre() -> None:
    f = front_of(DOOR_OBJ)
    plan = cavity_probe(f, 0.03)
    np.testing.assert_allclose(plan.spawn, [-0.75, 0.49 + 0.24, 0.32])  # back face + depth / 2
    assert plan.radius == pytest.approx(0.03)
    np.testing.assert_allclose(sorted(plan.box.half), sorted([0.29, 0.24, 0.24]))
    assert plan.box.contains(np.array([-0.75, 0.96, 0.05])) and not plan.box.contains(np.array([-0.75, 0.45, 0.3]))


def test_drawer_cavity_probe_is_dropped_into_the_pulled_out_part() -> None:
    """Pulled out by 0.4 m: the probe goes 0.2 m behind the front (half of what is out) at mid height,
    then moves with the drawer: y = 0.49 + 0.2 - 0.4."""
    plan = cavity_probe(front_of(DRAWER_OBJ), 0.03)
    np.testing.assert_allclose(plan.spawn, [0.3, 0.29, 0.17], atol=1e-12)
    np.testing.assert_allclose(plan.box.center, [0.3, 0.49 + 0.24 - 0.4, 0.17], atol=1e-12)


def test_cavity_probe_is_dropped_from_at_most_the_drop_height() -> None:
    """The door's cavity spans z 0.03..0.61 (0.32 +- 0.29); a 0.03 m probe at its centre is 0.26 m above
    the floor: with a 0.1 m drop it falls from z = 0.03 + 0.03 + 0.1 = 0.16, straight below the centre,
    which is kept as the point checked for clearance. The drawer's probe (z 0.17, cavity floor 0.03) is
    0.11 m up: lowered by 0.01 to 0.16. A 0.3 m drop leaves both where they were."""
    f = front_of(DOOR_OBJ)
    plan = cavity_probe(f, 0.03, drop=0.1)
    np.testing.assert_allclose(plan.spawn, [-0.75, 0.73, 0.16], atol=1e-12)
    np.testing.assert_allclose(plan.center, [-0.75, 0.73, 0.32], atol=1e-12)
    np.testing.assert_allclose(cavity_probe(f, 0.03, drop=0.3).spawn, [-0.75, 0.73, 0.32], atol=1e-12)
    drawer = cavity_probe(front_of(DRAWER_OBJ), 0.03, drop=0.1)
    np.testing.assert_allclose(drawer.spawn, [0.3, 0.29, 0.16], atol=1e-12)
    np.testing.assert_allclose(drawer.center, [0.3, 0.29, 0.17], atol=1e-12)
    assert fell_enough(plan.box, plan.spawn, np.array([-0.75, 0.73, 0.11]), 0.03)  # half of 0.1


def test_probe_shrinks_for_small_fronts() -> None:
    small = DOOR_OBJ.model_copy(update={"obb": OBB(center=(0, 0, 0), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)),
                                                   extents=(0.15, 0.1, 0.02))})
    assert probe_radius(front_of(small), 0.03) == pytest.approx(0.015)


def test_fell_enough_is_half_of_the_free_drop() -> None:
    box = CavityBox(np.array([0, 0, 0.27]), np.eye(3), np.array([0.2, 0.2, 0.24]))  # bottom face at z = 0.03
    spawn = np.array([0, 0, 0.32])  # free drop to the bottom: 0.32 - (0.03 + 0.03) = 0.26
    assert fell_enough(box, spawn, np.array([0, 0, 0.19]), 0.03)  # came down 0.13 = half
    assert not fell_enough(box, spawn, np.array([0, 0, 0.20]), 0.03)


def test_front_probe_and_advance() -> None:
    f = front_of(DOOR_OBJ)
    plan = front_probe(f, 0.03, 1.0)
    np.testing.assert_allclose(plan.start, [-0.75, 0.47 - 0.08, 0.32])
    np.testing.assert_allclose(plan.velocity, [0, 1, 0])
    # measured from the back face (y = 0.49): a front's box includes its handles
    assert advance(f, np.array([-0.75, 0.47, 0.32]), 0.03) == pytest.approx(0.01)
    assert advance(f, plan.start, 0.03) == pytest.approx(-0.07)


def test_joints_match_by_geometry_whatever_their_names() -> None:
    fronts = [front_of(DOOR_OBJ), front_of(DRAWER_OBJ)]
    joints = [JointPose("drawer_03_joint", "prismatic", np.array([0.3, 0.48, 0.17]), np.array([0, -1.0, 0])),
              JointPose("door_01_joint", "revolute", np.array([-0.99, 0.48, 0.325]), np.array([0, 0, -1.0])),
              JointPose("flap_joint", "revolute", np.array([-0.99, 0.48, 0.32]), np.array([1.0, 0, 0]))]  # wrong axis
    m = match_joints(fronts, joints)
    assert {k: v.object_id for k, v in m.items()} == {"drawer_03_joint": "drawer", "door_01_joint": "door"}
    # far from the geometry, the object id in the name still matches
    named = [JointPose("door__joint", "revolute", np.array([5.0, 5, 5]), np.array([0, 0, 1.0]))]
    assert {k: v.object_id for k, v in match_joints(fronts, named).items()} == {"door__joint": "door"}


def test_effective_inertia_of_a_plate_about_its_edge() -> None:
    """A 3 kg plate 0.5 m wide hinged at one edge: I = m w^2 / 12 + m (w / 2)^2 = m w^2 / 3 = 0.25."""
    m, w = 3.0, 0.5
    Ic = np.diag([1.0, 1.0, m * w * w / 12])  # about its centre; only the z row matters for a z hinge
    assert effective_inertia("revolute", np.array([0, 0, -1.0]), np.zeros(3), m, np.array([0.25, 0, 0.7]), Ic) == pytest.approx(0.25)
    assert effective_inertia("prismatic", np.array([0, 1.0, 0]), np.zeros(3), m, np.array([0.25, 0, 0]), Ic) == pytest.approx(3.0)


def test_gains_are_critically_damped_at_the_drive_frequency() -> None:
    j = SimJoint("j", "revolute", np.zeros(3), np.array([0, 0, 1.0]), "l", 0.0, 1.0, 0.25)
    kp, kd = drive.gains([j], PhysicsConfig(drive_hz=5.0))
    assert kp[0] == pytest.approx(0.25 * (10 * np.pi) ** 2) and kd[0] == pytest.approx(2 * 0.25 * 10 * np.pi)
    assert kd[0] ** 2 == pytest.approx(4 * 0.25 * kp[0])  # zeta = 1


def test_target_trajectory_opens_holds_closes() -> None:
    goal, T, hold = 1.2, 2.0, 0.5
    assert drive.target(0.0, goal, T, hold) == (0.0, 0.0)
    q, v = drive.target(1.0, goal, T, hold)  # mid-way: s = 1/2, s' = 3/2
    assert q == pytest.approx(0.6) and v == pytest.approx(goal * 1.5 / T)
    assert drive.target(2.2, goal, T, hold) == (goal, 0.0)
    q, v = drive.target(3.5, goal, T, hold)
    assert q == pytest.approx(0.6) and v == pytest.approx(-goal * 1.5 / T)
    assert drive.target(9.0, goal, T, hold) == (0.0, 0.0)
    door = SimJoint("j", "revolute", np.zeros(3), np.array([0, 0, 1.0]), "l", 0.0, np.pi / 2, 0.2)
    drawer = SimJoint("k", "prismatic", np.zeros(3), np.array([0, 1.0, 0]), "m", 0.0, 0.1, 3.0)
    cfg = PhysicsConfig()
    assert drive.move_time(door, cfg) == pytest.approx(np.pi / 2)  # 1 rad/s
    assert drive.move_time(drawer, cfg) == pytest.approx(cfg.min_move_s)  # 0.1 m at 0.5 m/s, clipped up


def test_instability_names_nan_and_blow_up() -> None:
    joints = [SimJoint("a", "revolute", np.zeros(3), np.array([0, 0, 1.0]), "la", 0, 1, 1),
              SimJoint("b", "prismatic", np.zeros(3), np.array([0, 1.0, 0]), "lb", 0, 1, 1)]
    vmax = np.array([20.0, 5.0])
    assert drive.instability(np.zeros(2), np.array([19.0, 4.9]), vmax, joints, 0.5) is None
    assert drive.instability(np.zeros(2), np.array([0.0, 6.0]), vmax, joints, 0.5).startswith("blow-up at 0.50 s (b")
    assert drive.instability(np.zeros(2), np.array([0.0, 6.0]), vmax, joints, 0.5, watch=[0]) is None
    assert drive.instability(np.array([np.nan, 0]), np.zeros(2), vmax, joints, 0.5, watch=[]) == "nan at 0.50 s"


def test_contact_log_keeps_the_deepest_per_body_in_first_contact_order() -> None:
    log = drive.ContactLog(frozenset({"part"}))
    log.add([Contact("part", "wall", -0.002, "p0", "w3"), Contact("floor", "part", 0.0005),
             Contact("a", "b", -0.5), Contact("part", "wall", -0.004, "p1", "w7")])
    assert log.order == ["wall", "floor"] and log.deepest == pytest.approx(0.004)
    assert [(t.body, t.depth, t.geom) for t in log.touches()] == [("wall", 0.004, "w7"), ("floor", 0.0, None)]


def test_engine_summary_counts() -> None:
    def joint(ok: bool, reached: float, pen: float, unstable: str | None = None) -> JointCheck:
        return JointCheck(joint="j", link="l", joint_type="revolute", lower=0, upper=1, reached=reached, returned=0,
                          penetration=pen, passed=ok, unstable=unstable)

    def probe(kind: str, ok: bool) -> ProbeCheck:
        return ProbeCheck(kind=kind, object_id="o", joint="j", radius=0.03, start=(0, 0, 0), end=(0, 0, 0), passed=ok)

    e = EngineCheck(engine="mujoco", status="ok", joints=[joint(True, 0.95, 0.002), joint(False, 0.5, 0.03),
                                                          joint(False, 0.91, 0.0, "nan at 1.00 s")],
                    probes=[probe("cavity", True), probe("front", False), probe("front", True)])
    s = e.summary(0.9)
    assert (s["joints"], s["passed"], s["reached"], s["unstable"]) == (3, 1, 2, 1)
    assert s["max_penetration"] == pytest.approx(0.03)
    assert (s["cavities_free"], s["cavities"], s["fronts_blocked"], s["fronts"]) == (1, 1, 1, 2)
    assert not e.passed
