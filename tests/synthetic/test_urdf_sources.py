"""URDF and scene-synthesizer sources: GT joints agree with the URDF's own kinematics."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from react3d_core.errors import InputError
from react3d_core.synthetic import generate_scene
from react3d_core.synthetic.from_urdf import MARGIN, build_from_urdf

URDF = """<?xml version="1.0"?>
<robot name="cab">
  <link name="world"/>
  <link name="corpus"><visual><origin xyz="0 0 0.4"/><geometry><box size="0.6 0.5 0.8"/></geometry></visual></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="corpus"/><origin xyz="1 2 0"/></joint>
  <link name="door"><visual><origin xyz="0.3 0 0"/><geometry><box size="0.58 0.02 0.38"/></geometry></visual></link>
  <joint name="door_hinge" type="revolute"><parent link="corpus"/><child link="door"/>
    <origin xyz="-0.29 -0.26 0.6"/><axis xyz="0 0 1"/><limit lower="-1.6" upper="0" effort="1" velocity="1"/></joint>
  <link name="door_handle"><visual><origin xyz="0.5 -0.03 0"/><geometry><box size="0.02 0.03 0.12"/></geometry></visual></link>
  <joint name="h" type="fixed"><parent link="door"/><child link="door_handle"/></joint>
  <link name="drawer"><visual><geometry><box size="0.58 0.02 0.3"/></geometry></visual>
    <visual><origin xyz="0 0.2 0"/><geometry><box size="0.5 0.3 0.2"/></geometry></visual></link>
  <joint name="slide" type="prismatic"><parent link="corpus"/><child link="drawer"/>
    <origin xyz="0 -0.26 0.2"/><axis xyz="0 -1 0"/><limit lower="0" upper="0.4" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.fixture()
def urdf_file(tmp_path: Path) -> Path:
    p = tmp_path / "cab.urdf"
    p.write_text(URDF)
    return p


def _child_world(u, link: str) -> np.ndarray:  # noqa: ANN001
    g = u.scene.graph
    out = []
    for node in g.nodes_geometry:
        if g.transforms.parents.get(node) == link:
            T, name = g[node]
            out.append(np.asarray(u.scene.geometry[name].vertices) @ T[:3, :3].T + T[:3, 3])
    return np.concatenate(out)


def test_urdf_joints_match_urdf_kinematics(urdf_file: Path) -> None:
    import yourdfpy

    layout = build_from_urdf(urdf_file, seed=0)
    arts = {p.key: p for p in layout.parts}
    assert set(arts) == {"door_hinge", "slide"}
    assert arts["door_hinge"].handle_key == "door_hinge.handle"
    u = yourdfpy.URDF.load(str(urdf_file))
    lo = np.asarray(layout.extra["offset"])  # the URDF is shifted into the room shell
    assert lo[0] >= MARGIN - 1.0
    closed = {k: _child_world(u, k) for k in ("door", "drawer")}
    for name, link, q_urdf in [("door_hinge", "door", -0.9), ("slide", "drawer", 0.25)]:
        cfg = {"door_hinge": 0.0, "slide": 0.0}
        cfg[name] = q_urdf
        u.update_cfg(np.array([cfg[n] for n in u.actuated_joint_names]))
        opened = _child_world(u, link) + lo
        a = arts[name].articulation
        assert a.lower == 0.0 and a.upper > 0
        # the door's URDF range is [-1.6, 0]: our axis is flipped so that q = +0.9 opens it
        q = abs(q_urdf)
        np.testing.assert_allclose(a.move(closed[link] + lo, q), opened, atol=1e-5)
        u.update_cfg(np.zeros(len(u.actuated_joint_names)))


def test_urdf_scene_writes_gt(urdf_file: Path, tmp_path: Path) -> None:
    out = generate_scene(tmp_path / "u", source="urdf", urdf_path=urdf_file, n_frames=4)
    meta = json.loads((out / "synth_meta.json").read_text())
    assert [p["type"] for p in meta["parts"]] == ["revolute", "prismatic"]


def test_unobserved_internal_geometry_is_culled(urdf_file: Path, tmp_path: Path) -> None:
    """The drawer's box sits inside the solid corpus: no camera sees it, so (as in a real scan) neither
    the mesh nor the drawer's GT faces keep it; the drawer front stays whole."""
    from react3d_core.data.mesh import load_mesh
    from react3d_core.ground_truth import read_articulate3d

    layout = build_from_urdf(urdf_file, seed=0)
    drawer_key = layout.key_ids["slide"]
    y_front = 2.0 - 0.25 + layout.extra["offset"][1]  # corpus front face in the scene frame
    full = layout.mesh.vertices[np.unique(layout.mesh.faces[layout.face_keys == drawer_key])]
    assert (full[:, 1] > y_front + 0.1).any()  # the box reaches deep into the corpus before culling

    out = generate_scene(tmp_path / "u", source="urdf", urdf_path=urdf_file, n_frames=4)
    meta = json.loads((out / "synth_meta.json").read_text())
    assert meta["culled_faces"] > 0 and meta["unobserved_parts"] == []
    mesh = load_mesh(out / "scans" / "mesh_aligned_0.05.ply")
    gt = read_articulate3d(out / "articulate3d")
    drawer = next(p for p in gt.movable if p.articulation.joint_type == "prismatic")
    v = mesh.vertices[drawer.vert_indices]
    assert v[:, 1].max() < y_front + 1e-3  # nothing of the drawer left inside the corpus
    front = v[v[:, 1] < y_front - 0.015]    # the front face (2 cm slab in front of the corpus)
    assert np.ptp(front[:, 0]) == pytest.approx(0.58, abs=0.01) and np.ptp(front[:, 2]) == pytest.approx(0.3, abs=0.01)


def test_bad_urdf_is_one_clear_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot><link")
    with pytest.raises(InputError, match="bad.urdf"):
        build_from_urdf(bad)
    with pytest.raises(InputError, match="not found"):
        build_from_urdf(tmp_path / "missing.urdf")


@pytest.mark.slow
def test_scene_synthesizer_kitchen_has_20_joints(tmp_path: Path) -> None:
    out = generate_scene(tmp_path / "ss", source="scene-synthesizer", seed=0, n_frames=6)
    meta = json.loads((out / "synth_meta.json").read_text())
    assert len(meta["parts"]) >= 20
    assert all("basket" not in j for j in [p["label"] for p in meta["parts"]])
    assert meta["skipped_joints"]
