"""Real physics in MuJoCo, PyBullet and SAPIEN on the hand-made door + drawer export (tests/physics/scenes.py):
the clean scene passes; background geometry through the door and in its cavity fails the joint and the
probe; a door whose front plate is missing lets the front probe through."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.config.physics import ENGINES, PhysicsConfig
from react3d_core.physics import EngineCheck, PhysicsCheck, check_output
from react3d_core.physics.check import check_engine

BACKGROUND = {"mujoco": "world", "pybullet": "background", "sapien": "background"}
"""The static background's body name in each engine (MJCF puts its geoms in the world body)."""

_runs: dict[tuple[str, str], EngineCheck] = {}


def run(out: Path, engine: str) -> EngineCheck:
    pytest.importorskip(engine)
    key = (str(out), engine)
    if key not in _runs:
        _runs[key] = check_output(out, PhysicsConfig(), (engine,)).engines[0]
    return _runs[key]


def by_object(e: EngineCheck) -> dict[str, object]:
    return {j.object_id: j for j in e.joints}


def probes(e: EngineCheck) -> dict[tuple[str, str], object]:
    return {(p.kind, p.object_id): p for p in e.probes}


@pytest.mark.parametrize("engine", ENGINES)
def test_clean_scene_opens_and_probes_pass(clean_out: Path, engine: str) -> None:
    e = run(clean_out, engine)
    assert e.status == "ok", e.reason
    assert e.rest is not None and e.rest.moving_contacts == 0  # nothing touches at rest
    joints = by_object(e)
    assert set(joints) == {"door", "drawer"}
    for j in joints.values():
        assert j.passed, (j.joint, j.causes)
        assert j.reached >= 0.98 and j.returned <= 0.02 and j.penetration <= 0.002 and j.unstable is None
        assert j.time_to_reach is not None and 0 < j.time_to_reach < 2.5
    assert len(e.probes) == 4 and all(p.passed for p in e.probes), [(p.kind, p.object_id, p.cause) for p in e.probes]
    cav = probes(e)
    # the door's probe lands on the cabinet's bottom board (top at z = 0.04), the drawer's in the drawer
    # (bottom board top at z = 0.07), both at rest with their centre one radius above it
    door, drawer = cav[("cavity", "door")], cav[("cavity", "drawer")]
    assert door.end[2] == pytest.approx(0.04 + door.radius, abs=0.006)
    assert drawer.end[2] == pytest.approx(0.07 + drawer.radius, abs=0.006)
    assert drawer.touched[0].body == "drawer"  # it fell into the drawer, not onto the cabinet
    front = cav[("front", "door")]
    assert front.touched[0].body == "door" and front.advance is not None and front.advance <= 0.01


@pytest.mark.parametrize("engine", ENGINES)
def test_overlapping_export_fails_and_names_the_cause(overlapping_out: Path, engine: str) -> None:
    e = run(overlapping_out, engine)
    assert e.status == "ok", e.reason
    joints = by_object(e)
    door = joints["door"]
    assert not door.passed
    assert door.touched and door.touched[0].body == BACKGROUND[engine]
    assert any(BACKGROUND[engine] in c for c in door.causes)
    assert e.rest is not None and e.rest.moving_contacts > 0 and e.rest.deepest > 0.01
    assert joints["drawer"].passed, joints["drawer"].causes  # the drawer has nothing in its way
    cav = probes(e)
    assert not cav[("cavity", "door")].passed
    assert cav[("cavity", "drawer")].passed
    assert not e.passed


@pytest.mark.parametrize("engine", ENGINES)
def test_a_front_without_collider_lets_the_probe_through(frontless_out: Path, engine: str) -> None:
    e = run(frontless_out, engine)
    p = probes(e)[("front", "door")]
    assert not p.passed and p.cause.startswith("passed through the front")
    assert p.advance is not None and p.advance > 0.05  # well into the cavity
    assert probes(e)[("front", "drawer")].passed


def test_engines_build_the_same_joints(clean_out: Path) -> None:
    """Anchor, axis and drive inertia agree across engines (the door: a 0.48 x 0.58 x 0.02 m plate of
    500 kg/m^3 plus its 4 x 3 x 10 cm handle, hinged at x = -0.99)."""
    from react3d_core.physics.check import _make

    plate = 0.48 * 0.58 * 0.02 * 500
    handle = 0.04 * 0.03 * 0.10 * 500
    inertia = plate * (0.48 ** 2 + 0.02 ** 2) / 12 + plate * (0.24 ** 2 + 0.0 ** 2) \
        + handle * (0.04 ** 2 + 0.03 ** 2) / 12 + handle * (0.41 ** 2 + 0.025 ** 2)
    files = {"mujoco": "export/mjcf/scene.xml", "pybullet": "export/urdf/scene.urdf", "sapien": "export/urdf/scene.urdf"}
    for engine in ENGINES:
        pytest.importorskip(engine)
        sim = _make(engine, clean_out / files[engine], PhysicsConfig())
        try:
            j = {x.name: x for x in sim.joints}
            np.testing.assert_allclose(j["door_joint"].anchor, [-0.99, 0.48, 0.32], atol=1e-6)
            np.testing.assert_allclose(j["door_joint"].axis, [0, 0, -1], atol=1e-6)
            np.testing.assert_allclose(j["drawer_joint"].axis, [0, -1, 0], atol=1e-6)
            assert j["door_joint"].inertia == pytest.approx(inertia, rel=0.02), engine
            assert (j["door_joint"].lower, j["door_joint"].upper) == pytest.approx((0, np.pi / 2))
            assert "door" in sim.moving and "door_base" not in sim.moving
        finally:
            sim.close()


def test_mujoco_check_is_deterministic(clean_out: Path) -> None:
    pytest.importorskip("mujoco")
    a, b = (check_output(clean_out, PhysicsConfig(), ("mujoco",)) for _ in range(2))

    def strip(c: PhysicsCheck) -> dict:
        d = c.model_dump(mode="json")
        d.pop("seconds"), d.pop("created")
        for e in d["engines"]:
            e.pop("seconds"), e.pop("cpu_seconds")
        return d

    assert strip(a) == strip(b)


def test_a_missing_engine_is_skipped_with_the_reason(clean_out: Path, monkeypatch) -> None:  # noqa: ANN001
    import react3d_core.physics.check as chk

    real = chk.find_spec
    monkeypatch.setattr(chk, "find_spec", lambda name: None if name == "sapien" else real(name))
    from react3d_core.data import InteractiveScene

    e = check_engine("sapien", clean_out, InteractiveScene.load(clean_out / "scene.json"), PhysicsConfig())
    assert e.status == "skipped" and "pip install sapien" in (e.reason or "")


def test_an_engine_without_its_format_is_skipped(clean_out: Path, tmp_path: Path) -> None:
    import shutil

    from react3d_core.data import InteractiveScene

    out = tmp_path / "urdf_only"
    shutil.copytree(clean_out, out)
    scene = InteractiveScene.load(out / "scene.json")
    scene.model_copy(update={"exports": {"urdf": scene.exports["urdf"]}}).save(out / "scene.json")
    check = check_output(out, PhysicsConfig(probes=False), ("mujoco",))
    assert check.engines[0].status == "skipped" and "MJCF" in check.engines[0].reason
    assert not check.passed  # nothing ran: nothing was shown to work


@pytest.mark.parametrize("engine", ENGINES)
def test_a_front_probe_floats_and_a_cavity_probe_falls(clean_out: Path, engine: str) -> None:
    # a front probe is gravity compensated (MuJoCo ignores a body's gravcomp set only at run time)
    pytest.importorskip(engine)
    from react3d_core.physics.check import _make

    cfg = PhysicsConfig()
    sim = _make(engine, clean_out / ("export/mjcf/scene.xml" if engine == "mujoco" else "export/urdf/scene.urdf"), cfg)
    q = np.zeros(len(sim.joints))
    start = np.array([0.0, -1.0, 1.0])  # in the room, 1 m above the floor, nothing near
    for gravity, drop in ((False, 0.0), (True, 0.5 * 9.81 * 0.2 ** 2)):
        sim.reset(q)
        sim.add_probe(start, np.zeros(3), 0.03, 0.1, gravity=gravity)
        for _ in range(int(round(0.2 / sim.dt))):
            sim.step(q, q)
        assert start[2] - sim.probe()[0][2] == pytest.approx(drop, abs=0.005), (engine, gravity)


def test_a_cavity_probe_resting_on_its_own_floor_has_fallen(clean_out: Path) -> None:
    """Dropped from 4 mm above the door's carcass floor, the probe cannot come down half of the way to the
    front's lower edge (the floor board lies between); it rests on the object's own carcass, so the cavity
    is free. With the fallen rule alone (half way) it would be called held up."""
    pytest.importorskip("mujoco")
    from react3d_core.data import InteractiveScene
    from react3d_core.data.mesh import load_mesh
    from react3d_core.physics import drive
    from react3d_core.physics.check import _make
    from react3d_core.physics.targets import cavity_box, cavity_probe, fell_enough, front_of, match_joints

    scene = InteractiveScene.load(clean_out / "scene.json")
    obj = next(o for o in scene.objects if o.articulation.joint_type == "revolute")
    f = front_of(obj)
    bottom = float(cavity_box(f).corners()[:, 2].min())
    z = np.unique(np.round(load_mesh(clean_out / obj.base_mesh).vertices[:, 2], 6))
    floor_top = float(z[1])  # the floor board's top: the second-lowest height of the carcass's boxes
    assert floor_top - bottom > 0.008
    cfg = PhysicsConfig(cavity_drop_m=floor_top - bottom + 0.004)
    sim = _make("mujoco", clean_out / "export/mjcf/scene.xml", cfg)
    i = next(k for k, j in enumerate(sim.joints) if match_joints([f], [j]))
    res = drive.cavity(sim, i, f, cfg)
    assert res.passed and {t.body for t in res.touched} <= {sim.joints[i].link, f"{sim.joints[i].link}_base"}, res
    plan = cavity_probe(f, cfg.probe_radius_m, drop=cfg.cavity_drop_m)
    assert not fell_enough(plan.box, plan.spawn, np.array(res.end), plan.radius)


def test_sapien_joints_take_the_urdfs_friction(clean_out: Path, tmp_path: Path) -> None:
    """SAPIEN's builder reads <dynamics friction> but never applies it (every joint kept PhysX's 0.05); the
    check applies the file's value. Written 0 it drives freely; a door written with friction 1 resists the
    check's drive and stops further from its limit, so the value reaches PhysX."""
    pytest.importorskip("sapien")
    import re
    import shutil

    from react3d_core.physics.check import _make

    out = tmp_path / "out"
    shutil.copytree(clean_out, out)
    urdf = out / "export" / "urdf" / "scene.urdf"
    sim = _make("sapien", urdf, PhysicsConfig())
    try:
        assert {j.name: float(j.friction) for _, j in sim.active} == {"door_joint": 0.0, "drawer_joint": 0.0}
    finally:
        sim.close()
    text = urdf.read_text()
    door = re.search(r'<joint name="door_joint".*?</joint>', text, re.S)
    assert door is not None
    urdf.write_text(text.replace(door.group(0), re.sub(r'friction="0"', 'friction="1"', door.group(0))))
    sim = _make("sapien", urdf, PhysicsConfig())
    try:
        assert {j.name: round(float(j.friction), 6) for _, j in sim.active} == {"door_joint": 1.0, "drawer_joint": 0.0}
    finally:
        sim.close()
    e = check_output(out, PhysicsConfig(probes=False), ("sapien",)).engines[0]
    joints = {j.joint: j for j in e.joints}
    assert joints["drawer_joint"].passed
    free = by_object(run(clean_out, "sapien"))["door"]
    assert free.passed and free.reached > 0.99
    assert joints["door_joint"].reached < free.reached - 0.02, (joints["door_joint"].reached, free.reached)
