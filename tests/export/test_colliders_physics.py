"""Exports are simulation-ready with collisions on: nothing overlaps at rest, every joint can be driven
open in MuJoCo, PyBullet and SAPIEN, open cavities are free, and walls and fronts still collide.

Scenes (tests/export/collider_scenes.py): a scanned cabinet whose face frame, overhanging worktop and
inner shelf a naive background collider bridges across the fronts, a door next to a side wall, and two
drawers whose carcasses were estimated at an angle and overlap.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from collider_scenes import (
    DOOR_PF,
    DRAWER,
    SHELF_Z,
    WALL_X,
    angled_carcasses_scene,
    cabinet_scene,
    mujoco_drive,
    pybullet_connect,
    pybullet_drive,
    sapien_drive,
)
from react3d_core.config.export import ExportConfig
from react3d_core.data import InteractiveScene
from react3d_core.export import export_scene
from react3d_core.export.clearance import gap, hull_obstacle, piece_axes
from react3d_core.export.collision import planar_patches
from react3d_core.export.model import build_scene_model

CONFIG = ExportConfig(texel_per_m=60)
BULLET_MARGIN = 0.001  # PyBullet's collision margin around a convex mesh (measured: two hulls 10 mm apart report 8 mm)
SCENES = {"cabinet": cabinet_scene, "angled": angled_carcasses_scene}


@pytest.fixture(scope="module")
def exports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Path]]:
    out = {}
    for name, build in SCENES.items():
        d = tmp_path_factory.mktemp(name)
        build(d)
        out[name] = export_scene(d / "scene.json", config=CONFIG, cache_dir=d / "cache")
    return out


def test_the_raw_background_bridges_the_fronts(tmp_path: Path) -> None:
    """The scene needs carving: slabs fitted to the scanned cabinet without it reach into the door."""
    cabinet_scene(tmp_path)
    scene = InteractiveScene.load(tmp_path / "scene.json")
    model = build_scene_model(scene, tmp_path, CONFIG)
    raw = planar_patches(model.link("background").static_mesh, CONFIG.background_patch_m, CONFIG.min_collision_thickness)
    door = [hull_obstacle(p.vertices, "door", "rest") for p in model.link("door").collisions]
    deepest = min(gap(p.vertices, piece_axes(p), ob)[0] for p in raw for ob in door)
    assert deepest < -0.01


@pytest.mark.parametrize("name", list(SCENES))
def test_no_collider_pair_overlaps_at_rest(exports: dict[str, dict[str, Path]], name: str) -> None:
    """PyBullet's closest points between every pair of links (its own convex hulls of our pieces; Bullet
    reports distances less the 1 mm collision margin it puts around each hull)."""
    pb, cid, body, names = pybullet_connect(exports[name]["urdf"])
    try:
        links = [-1, *names.values()]  # -1: the root link (world, no colliders)
        close = []
        for i, a in enumerate(links):
            for b in links[i + 1 :]:
                pts = pb.getClosestPoints(body, body, CONFIG.collider_clearance_m - 2 * BULLET_MARGIN - 1e-4, a, b, physicsClientId=cid)
                close += [(a, b, p[8]) for p in pts]
        assert close == []
    finally:
        pb.disconnect(cid)


@pytest.mark.parametrize("name", list(SCENES))
@pytest.mark.parametrize("engine", ["mujoco", "pybullet", "sapien"])
def test_each_joint_opens_with_collisions_on(exports: dict[str, dict[str, Path]], name: str, engine: str) -> None:
    pytest.importorskip(engine)
    drive = {"mujoco": mujoco_drive, "pybullet": pybullet_drive, "sapien": sapien_drive}[engine]
    contacts, deepest, reached = drive(exports[name]["mjcf" if engine == "mujoco" else "urdf"])
    assert contacts == 0 and deepest == 0.0
    assert len(reached) == 2 and all(f >= 0.9 for f in reached.values()), reached


def _drop(pb, cid, pos, radius: float = 0.03, velocity=(0, 0, 0), steps: int = 480) -> np.ndarray:  # noqa: ANN001
    shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=radius, physicsClientId=cid)
    ball = pb.createMultiBody(0.1, shape, basePosition=list(pos), physicsClientId=cid)
    pb.resetBaseVelocity(ball, list(velocity), physicsClientId=cid)
    for _ in range(steps):
        pb.stepSimulation(physicsClientId=cid)
    return np.asarray(pb.getBasePositionAndOrientation(ball, physicsClientId=cid)[0])


def _hold(pb, cid, body, names: dict[str, int], q: dict[str, float]) -> None:  # noqa: ANN001
    for name, j in names.items():
        if name.endswith("_joint"):
            pb.resetJointState(body, j, q.get(name, 0.0), physicsClientId=cid)
            pb.setJointMotorControl2(body, j, pb.POSITION_CONTROL, targetPosition=q.get(name, 0.0), force=500, physicsClientId=cid)


def test_open_cavities_are_free(exports: dict[str, dict[str, Path]]) -> None:
    pb, cid, body, names = pybullet_connect(exports["cabinet"]["urdf"])
    try:
        _hold(pb, cid, body, names, {"drawer_joint": DRAWER.upper, "door_joint": np.pi / 2})
        # into the open drawer: it comes to rest on the drawer box's bottom, inside the box
        x, y, z = _drop(pb, cid, (0.30, 0.49 - DRAWER.upper + 0.25, 0.85))
        assert 0.0 < x < 0.6 and 0.49 - DRAWER.upper < y < 0.95 - DRAWER.upper and 0.42 < z < 0.55
        # into the open door's carcass, above the scanned shelf: the carcass is hollow, it falls to its bottom
        c = DOOR_PF.center
        x, y, z = _drop(pb, cid, (c[0], 0.75, SHELF_Z + 0.1))
        assert z < SHELF_Z - 0.1 and 0.5 < y < 1.0
    finally:
        pb.disconnect(cid)


def test_background_and_closed_fronts_still_collide(exports: dict[str, dict[str, Path]]) -> None:
    pb, cid, body, names = pybullet_connect(exports["cabinet"]["urdf"])
    try:
        _hold(pb, cid, body, names, {})
        # thrown at the side wall beyond the door's path: bounces off the wall
        x, _, _ = _drop(pb, cid, (WALL_X + 0.3, -0.6, 0.3), velocity=(-3, 0, 0), steps=240)
        assert x > WALL_X
        # onto the worktop: stays on it
        _, _, z = _drop(pb, cid, (0.0, 0.8, 1.0))
        assert z > 0.75
        # thrown at the closed drawer and the closed door: stopped in front of them
        for pos in ((0.3, 0.2, 0.55), (DOOR_PF.center[0], 0.2, 0.3)):
            _, y, _ = _drop(pb, cid, pos, velocity=(0, 3, 0), steps=120)
            assert y < 0.47
    finally:
        pb.disconnect(cid)


def test_each_format_states_its_collision_policy(exports: dict[str, dict[str, Path]]) -> None:
    from pxr import Usd, UsdPhysics

    from react3d_core.export.usd import PHYSX_ARTICULATION_API, SELF_COLLISIONS

    out = exports["cabinet"]
    mj = ET.parse(out["mjcf"]).getroot()
    assert mj.find("default/default[@class='collision']/geom").get("contype") == "1"
    assert mj.find("default/default[@class='collision']/geom").get("conaffinity") == "1"
    pairs = {(e.get("body1"), e.get("body2")) for e in mj.findall("contact/exclude")}
    assert pairs == {("door_base", "door"), ("drawer_base", "drawer")}
    assert "Collision policy" in out["urdf"].read_text()
    stage = Usd.Stage.Open(str(out["usd"]))
    for oid in ("door", "drawer"):
        root = stage.GetPrimAtPath(f"/World/{oid}")
        assert root.HasAPI(UsdPhysics.ArticulationRootAPI)
        # PhysxSchema is not registered in usd-core: the applied token is in the prim's metadata
        assert PHYSX_ARTICULATION_API in root.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
        assert root.GetAttribute(SELF_COLLISIONS).Get() is True
        joint = UsdPhysics.Joint(stage.GetPrimAtPath(f"/World/{oid}/{oid}_joint"))
        assert joint.GetCollisionEnabledAttr().Get() is False
        targets = UsdPhysics.FilteredPairsAPI(stage.GetPrimAtPath(f"/World/{oid}/{oid}_base")).GetFilteredPairsRel().GetTargets()
        assert targets and all(str(t).startswith("/World/background/") for t in targets)
        assert all(stage.GetPrimAtPath(t).HasAPI(UsdPhysics.CollisionAPI) for t in targets)
    # the background's faces in a part's path or a carcass are kept for the eye only
    visual_only = stage.GetPrimAtPath("/World/background/background_visual_0_visual_only")
    assert visual_only.IsValid() and not visual_only.HasAPI(UsdPhysics.CollisionAPI)
