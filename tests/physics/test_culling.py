"""Contact culling of the physics check (react3d_core/physics/reach.py, drive.Culling): the swept boxes
computed by hand, and in real engines on the hand-made scene with a held plate in the drawer's way
(tests/physics/scenes.py, ``blocker=True``): parts far from the driven one sit out and change nothing,
the plate near the drawer still stops it, and every result equals the one with every collider on."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from react3d_core.config.physics import PhysicsConfig
from react3d_core.physics import check_output, reach
from react3d_core.physics.check import FORMAT, _make, load_output
from react3d_core.physics.drive import culling
from react3d_core.physics.sim import SimJoint

CULLED = ("mujoco", "pybullet", "sapien")
"""Engines that take links out of contacts (all three)."""


def joint(kind: str, axis: tuple[float, float, float], anchor: tuple[float, float, float] = (0, 0, 0)) -> SimJoint:
    return SimJoint("j", kind, np.array(anchor, float), np.array(axis, float), "part", 0.0, 1.0, 1.0)


def test_swept_box_of_a_slide_is_the_box_at_both_ends() -> None:
    box = np.array([[0, 0, 0], [1, 0.5, 0.2]], float)
    out = reach.swept(box, joint("prismatic", (0, -1, 0)), 0.0, 0.4)
    assert out == pytest.approx(np.array([[0, -0.4, 0], [1, 0.5, 0.2]]))


def test_swept_box_of_a_quarter_turn_hand_computed() -> None:
    # a 1 x 0.1 x 1 plate from x = 1 to 2 on a hinge along z through the origin, turned 0..90 degrees: at 0 it
    # spans x in [1, 2], y in [0, 0.1]; at 90 x in [-0.1, 0], y in [1, 2]; its far corner (2, 0.1) reaches
    # y = sqrt(2^2 + 0.1^2) = 2.0025 at atan(20) = 87.1 degrees, and x never passes 2
    box = np.array([[1, 0, 0], [2, 0.1, 1]], float)
    out = reach.swept(box, joint("revolute", (0, 0, 1)), 0.0, math.pi / 2)
    lo, hi = out
    pad = 2.0025 * (1 - math.cos(reach.STEP_RAD / 2))
    assert lo == pytest.approx([-0.1, 0, 0], abs=pad + 1e-9)
    assert hi[0] == pytest.approx(2, abs=pad + 1e-9) and hi[2] == pytest.approx(1, abs=pad + 1e-9)
    assert math.sqrt(4.01) - 1e-9 <= hi[1] <= math.sqrt(4.01) + pad + 1e-9


def test_motion_range_and_needed_links() -> None:
    assert reach.motion_range(1.0, 0.1) == pytest.approx((-0.1, 1.1))
    assert reach.motion_range(-0.4, 0.25) == pytest.approx((-0.5, 0.1))
    boxes = {"near": np.array([[1.04, 0, 0], [2, 1, 1]]), "far": np.array([[1.06, 0, 0], [2, 1, 1]])}
    region = np.array([[0, 0, 0], [1, 1, 1]], float)
    assert reach.needed(boxes, region, 0.05, keep=("part",)) == {"part", "near"}


@pytest.mark.parametrize("engine", CULLED)
def test_far_parts_sit_out_and_the_near_plate_stays_in(blocker_out: Path, engine: str) -> None:
    pytest.importorskip(engine)
    root, scene = load_output(blocker_out)
    cfg = PhysicsConfig()
    sim = _make(engine, root / scene.exports[FORMAT[engine]], cfg)
    try:
        cull = culling(sim, cfg)
        assert cull is not None
        names = [j.name for j in sim.joints]
        door, drawer, blocker = (names.index(f"{o}_joint") for o in ("door", "drawer", "blocker"))
        regions = {i: cull.swept(sim, i, *reach.motion_range(sim.joints[i].upper, cfg.cull_overshoot)) for i in (door, drawer)}
        assert cull.links(door, regions[door]) == {"door"}  # the drawer (0.5 m away) and the plate sit out
        assert cull.links(drawer, regions[drawer]) == {"drawer", "blocker"}  # the plate is in the drawer's way
        assert cull.carried[blocker] == {"blocker"}
    finally:
        sim.close()


@pytest.mark.parametrize("engine", CULLED)
def test_culled_check_equals_the_full_one(blocker_out: Path, engine: str) -> None:
    pytest.importorskip(engine)
    culled = check_output(blocker_out, PhysicsConfig(), (engine,)).engines[0]
    full = check_output(blocker_out, PhysicsConfig(cull_contacts=False), (engine,)).engines[0]
    assert culled.status == full.status == "ok"
    info = culled.settings["contact_culling"]
    assert "contact_culling" not in full.settings
    # 3 drives, 3 front probes, 2 cavity probes; the drawer touches the held plate, so its drive runs again in full
    assert info["episodes_culled"] + info["episodes_rerun_in_full"] == 8
    assert info["reruns"] == ["drive drawer_joint: touched held blocker"]
    drawer = next(j for j in culled.joints if j.object_id == "drawer")
    assert drawer.reached < 0.7 and [t.body for t in drawer.touched] == ["blocker"]
    # MuJoCo and Bullet give the same numbers to the bit; PhysX solves a smaller set of contact pairs in another order
    # (float32), so a probe may end some micrometres elsewhere
    tol = 1e-4 if engine == "sapien" else 0.0
    assert culled.rest == full.rest
    for a, b in zip(culled.joints, full.joints, strict=True):
        assert (a.joint, a.passed, a.causes, [t.body for t in a.touched]) == (b.joint, b.passed, b.causes, [t.body for t in b.touched])
        assert (a.reached, a.returned, a.penetration) == pytest.approx((b.reached, b.returned, b.penetration), abs=tol)
    for a, b in zip(culled.probes, full.probes, strict=True):
        assert (a.kind, a.object_id, a.passed, a.cause, [t.body for t in a.touched]) == (b.kind, b.object_id, b.passed, b.cause,
                                                                                      [t.body for t in b.touched])
        assert np.asarray(a.end) == pytest.approx(np.asarray(b.end), abs=tol)
        assert a.penetration == pytest.approx(b.penetration, abs=tol)


def test_a_joint_past_its_assumed_range_runs_again_in_full(blocker_out: Path) -> None:
    pytest.importorskip("mujoco")
    # with no overshoot allowed, MuJoCo's door (it ends a hair past its limit: reached 1.001) leaves its range
    culled = check_output(blocker_out, PhysicsConfig(cull_overshoot=0.0), ("mujoco",)).engines[0]
    full = check_output(blocker_out, PhysicsConfig(cull_contacts=False), ("mujoco",)).engines[0]
    reruns = culled.settings["contact_culling"]["reruns"]
    assert any(r.startswith("drive door_joint: left its assumed range") for r in reruns), reruns
    assert [j.model_dump() for j in culled.joints] == [j.model_dump() for j in full.joints]


def test_mujoco_comes_back_whole_after_a_probe_resized_while_culled(blocker_out: Path) -> None:
    # resizing the probe recomputes MuJoCo's per-body collision bits from the geoms as they are (mj_setConst):
    # taking every link back in must restore the bodies' bits too, or a link stays out of contacts for good
    pytest.importorskip("mujoco")
    root, scene = load_output(blocker_out)
    sim = _make("mujoco", root / scene.exports["mjcf"], PhysicsConfig())
    m = sim.m
    body0, geom0 = m.body_contype.copy(), m.geom_contype.copy()
    sim.reset(np.zeros(len(sim.joints)))
    sim.collide_only(frozenset({"door"}))
    assert m.body_contype[sim.body_id["drawer"]] == 0 and m.body_contype[sim.body_id["door"]] != 0
    sim.add_probe(np.array([0.3, 0.3, 0.5]), np.zeros(3), 0.011, 0.1, gravity=False)  # a new radius: mj_setConst
    sim.collide_only(None)
    assert (m.body_contype == body0).all() and (m.geom_contype == geom0).all()
