"""Labels from the evidence (one test per rule), names numbered in spatial order, stable across runs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from benchmarks import ablation_refinement
from react3d_core.assembly.naming import appliance_tag, floor_height, object_ids, part_label
from react3d_core.config.assembly import AssemblyConfig
from react3d_core.data import Articulation, TriMesh

CFG = AssemblyConfig()
X, Z, Y = np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([0, 1.0, 0])


def label(joint: str, axis, origin_z: float, centre_z: float, width: float, height: float, sliding: bool = False,  # noqa: ANN001
          tag: str | None = None, floor: float = 0.0) -> str:
    """A front facing -y (the room), centred at x = 0, ``width`` along x and ``height`` along z."""
    art = Articulation(joint_type=joint, axis=axis, origin=(0.0, 0.5, origin_z), lower=0.0, upper=1.0)
    return part_label(art, np.array([0.0, 0.5, centre_z]), X, Z, width, height, sliding, floor, CFG, tag)


def test_prismatic_parts_are_drawers_or_sliding_doors() -> None:
    assert label("prismatic", (0, -1, 0), 0.5, 0.5, 0.6, 0.2) == "drawer"
    assert label("prismatic", (1, 0, 0), 1.0, 1.0, 0.8, 1.8, sliding=True) == "sliding_door"
    assert label("prismatic", (0, -1, 0), 0.5, 0.5, 0.6, 0.2, tag="freezer drawer") == "drawer"  # appliances are hinged


def test_a_vertical_hinge_is_a_door() -> None:
    assert label("revolute", (0, 0, -1), 0.4, 0.4, 0.5, 0.7) == "door"
    assert label("revolute", (0.1, 0, 0.99), 1.0, 1.0, 0.9, 2.0) == "door"  # a room door, axis 6 deg off vertical
    assert label("revolute", (0, 0, 1), 1.0, 1.0, 0.6, 1.8) == "door"  # tall: a fridge only if perception says so


def test_perception_tags_name_appliance_doors() -> None:
    assert appliance_tag("Refrigerator door") == "fridge_door" and appliance_tag("freezer") == "fridge_door"
    assert appliance_tag("oven") == "oven_door" and appliance_tag("microwave oven") == "microwave_door"
    assert appliance_tag("kitchen_cabinet.door_3") is None and appliance_tag(None) is None
    assert label("revolute", (0, 0, 1), 1.0, 1.0, 0.6, 1.8, tag="refrigerator door") == "fridge_door"
    assert label("revolute", (0, 0, 1), 1.5, 1.5, 0.5, 0.3, tag="microwave") == "microwave_door"
    assert label("revolute", (1, 0, 0), 0.1, 0.45, 0.6, 0.7, tag="dishwasher") == "dishwasher_door"


def test_a_bottom_hinged_front_at_floor_level_is_a_dishwasher_door() -> None:
    # 60 cm wide, 72 cm tall on a 10 cm plinth, hinged at its bottom edge, under a 0.9 m worktop
    assert label("revolute", (1, 0, 0), 0.1, 0.46, 0.6, 0.72) == "dishwasher_door"
    assert label("revolute", (1, 0, 0), 0.1, 0.46, 0.6, 0.72, floor=-0.3) == "flap"  # floor 0.3 m lower: the front is 0.4-1.12 m up


def test_a_shorter_bottom_hinged_appliance_front_is_an_oven_door() -> None:
    assert label("revolute", (-1, 0, 0), 0.3, 0.55, 0.6, 0.5) == "oven_door"  # above a drawer, under the worktop
    assert label("revolute", (1, 0, 0), 0.1, 0.375, 0.6, 0.55) == "oven_door"  # at floor level but under 0.6 m tall: not a dishwasher


def test_other_horizontal_hinges_are_flaps() -> None:
    assert label("revolute", (1, 0, 0), 1.9, 1.7, 0.6, 0.4) == "flap"  # top-hinged wall cabinet front
    assert label("revolute", (1, 0, 0), 0.7, 0.78, 0.6, 0.16) == "flap"  # tilt-out sink front: too low for an oven
    assert label("revolute", (1, 0, 0), 1.5, 1.8, 0.6, 0.6) == "flap"  # bottom-hinged but high up: a wall cabinet flap
    assert label("revolute", (1, 0, 0), 0.1, 0.46, 1.0, 0.72) == "flap"  # too wide for an appliance
    lid = Articulation(joint_type="revolute", axis=(1, 0, 0), origin=(0, 0.3, 0.9), lower=0.0, upper=1.0)
    assert part_label(lid, np.array([0, 0.5, 0.9]), X, Y, 0.6, 0.4, False, 0.0, CFG) == "flap"  # a lid facing up


def test_floor_height_ignores_stray_low_faces_and_worktops() -> None:
    floor = trimesh.creation.box(extents=(4, 4, 0.02)).apply_translation((0, 0, 0.04))  # top at 0.05
    worktop = trimesh.creation.box(extents=(2, 0.6, 0.04)).apply_translation((0, 1, 0.9))
    stray = trimesh.Trimesh([[0, 0, -0.3], [0.01, 0, -0.3], [0, 0.01, -0.3]], [[0, 1, 2]])
    m = trimesh.util.concatenate([floor, worktop, stray])
    mesh = TriMesh(np.asarray(m.vertices), np.asarray(m.faces), np.zeros((len(m.vertices), 3), np.uint8))
    assert floor_height(mesh) == pytest.approx(0.05)


def test_ids_are_numbered_per_label_in_spatial_order() -> None:
    labels = ["drawer", "door", "drawer", "drawer", "door"]
    centres = [(1.0, 0.5, 0.3), (0.2, 0.5, 0.4), (1.0, 0.5, 0.7), (1.01, 0.51, 0.5), (-0.5, 0.5, 0.4)]
    ids = object_ids(labels, centres)
    # a column of drawers (same 5 cm cell) from the top down; doors from left to right
    assert ids == ["drawer_03", "door_02", "drawer_01", "drawer_02", "door_01"]
    order = [3, 0, 4, 2, 1]
    assert object_ids([labels[i] for i in order], [centres[i] for i in order]) == [ids[i] for i in order]
    many = object_ids(["flap"] * 120, [(0.1 * k, 0, 0) for k in range(120)])
    assert many[0] == "flap_001" and many[-1] == "flap_120" and len(set(many)) == 120


def test_names_are_stable_across_runs(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    """Two assemblies of the same parts, found in opposite orders: the same names for the same parts."""
    from react3d_core.assembly import assemble_scene
    from react3d_core.config import PipelineConfig

    root = synthetic_scene(seed=3, n_frames=16, kind="dresser")
    scene, mesh, pairs = ablation_refinement.oracle_parts(root, seed=0)
    parts = [p for p, _ in pairs]
    runs = []
    for k, order in enumerate((parts, parts[::-1])):
        m = assemble_scene(scene, mesh, order, PipelineConfig(), tmp_path / f"run{k}")
        runs.append({tuple(np.round(o.obb.center, 6)): (o.object_id, o.label) for o in m.objects})
        assert (tmp_path / f"run{k}" / "meshes" / m.objects[0].object_id / "part.ply").is_file()
    assert runs[0] == runs[1]
    names = [n for n, _ in runs[0].values()]
    assert len(set(names)) == len(names) == len(parts)
    assert all(n.rsplit("_", 1)[0] in ("drawer", "door", "flap", "sliding_door") for n in names)
    assert any(n.startswith("drawer_") for n in names)  # a dresser has drawers
