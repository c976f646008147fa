"""The joint faults found on articulated assets from other projects, on a hand-made URDF of the same kind
(a carcass of boards, drawers with their boxes, doors), made a scan by ``synth --source urdf`` and
converted with oracle perception:

- drawers whose GT part includes their box look flat with an in-plane axis to the oracle, which called
  them sliding; the in-plane snap turned them 72-90 deg off their front normal;
- a drawer in a tall unit whose top no camera saw got a travel from the cavity ray that flew through
  the unseen back (up to the 1.2 m clamp), or from the floor's scan ending under it (0.13 m);
- a door hinged beside a wall must stop before it swings into it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

T = 0.018  # board thickness
CHEST_DEPTH, TALL_DEPTH = 0.48, 0.58
WALL_X = 2.795  # the wall's face beside the third station's hinge (before the scene's offset)
JOINTS = ["chest_drawer_l", "chest_drawer_r", "chest_drawer_wide", "chest_door_l", "chest_door_r", "tall_drawer_1",
          "tall_drawer_2", "tall_door", "wall_door"]  # the movable joints in URDF order


def _box(size: tuple[float, float, float], xyz: tuple[float, float, float]) -> str:
    return (f'<visual><origin xyz="{xyz[0]:.4f} {xyz[1]:.4f} {xyz[2]:.4f}"/>'
            f'<geometry><box size="{size[0]:.4f} {size[1]:.4f} {size[2]:.4f}"/></geometry></visual>')


def _carcass(x0: float, W: float, D: float, H: float, dividers: tuple[tuple[float, float, float], ...] = ()) -> list[str]:
    """Boards of a body x in [x0, x0 + W], y in [0, D] (fronts on y = 0, facing -y), z in [0, H]."""
    v = [_box((W, D, T), (x0 + W / 2, D / 2, H - T / 2)), _box((W, D, T), (x0 + W / 2, D / 2, T / 2)),
         _box((T, D, H), (x0 + T / 2, D / 2, H / 2)), _box((T, D, H), (x0 + W - T / 2, D / 2, H / 2)),
         _box((W, T, H), (x0 + W / 2, D - T / 2, H / 2))]
    v += [_box((T, D - T, z1 - z0), (x, (D - T) / 2, (z0 + z1) / 2)) for x, z0, z1 in dividers]
    return v


def _drawer(name: str, x0: float, x1: float, z0: float, z1: float, box_depth: float, travel: float) -> str:
    """A drawer front with its box (bottom, sides, back) and a bar handle, pulled out along -y."""
    w, h = x1 - x0, z1 - z0
    bw, bh = w - 2 * T - 0.01, h - 0.04
    vis = [_box((w - 0.004, T, h - 0.004), (0, -T / 2, 0)),
           _box((bw, box_depth, 0.01), (0, box_depth / 2, -h / 2 + 0.03)),
           _box((0.01, box_depth, bh), (-bw / 2, box_depth / 2, -h / 2 + 0.02 + bh / 2)),
           _box((0.01, box_depth, bh), (bw / 2, box_depth / 2, -h / 2 + 0.02 + bh / 2)),
           _box((bw, 0.01, bh), (0, box_depth, -h / 2 + 0.02 + bh / 2))]
    return (f'<link name="{name}">{"".join(vis)}</link>'
            f'<joint name="{name}_slide" type="prismatic"><parent link="body"/><child link="{name}"/>'
            f'<origin xyz="{(x0 + x1) / 2:.4f} 0 {(z0 + z1) / 2:.4f}"/><axis xyz="0 -1 0"/>'
            f'<limit lower="0" upper="{travel}" effort="1" velocity="1"/></joint>'
            f'<link name="{name}_handle">{_box((min(0.2, w / 3), 0.025, 0.02), (0, -T - 0.0125, 0))}</link>'
            f'<joint name="{name}_h" type="fixed"><parent link="{name}"/><child link="{name}_handle"/></joint>\n')


def _door(name: str, x0: float, x1: float, z0: float, z1: float, hinge: str) -> str:
    """A door slab on y in [-T, 0] hinged on its left or right edge; q > 0 swings it out (-y)."""
    w = x1 - x0
    hx, sx, axis = (x0, 1.0, "0 0 -1") if hinge == "left" else (x1, -1.0, "0 0 1")
    return (f'<link name="{name}">{_box((w - 0.004, T, z1 - z0 - 0.004), (sx * w / 2, -T / 2, 0))}</link>'
            f'<joint name="{name}_hinge" type="revolute"><parent link="body"/><child link="{name}"/>'
            f'<origin xyz="{hx:.4f} 0 {(z0 + z1) / 2:.4f}"/><axis xyz="{axis}"/>'
            f'<limit lower="0" upper="1.57" effort="1" velocity="1"/></joint>'
            f'<link name="{name}_handle">{_box((0.02, 0.025, 0.12), (sx * (w - 0.05), -T - 0.0125, 0))}</link>'
            f'<joint name="{name}_h" type="fixed"><parent link="{name}"/><child link="{name}_handle"/></joint>\n')


def cabinets_urdf() -> str:
    """Three stations along x, fronts facing -y: a 1.2 x 0.48 x 0.8 chest (two drawers side by side, a wide
    drawer, two doors), a 0.6 x 0.58 x 2.1 tall unit (two drawers at the bottom, a door above), a base unit
    with a wall 5 mm beside its left side, where its door is hinged."""
    body = _carcass(0.0, 1.2, CHEST_DEPTH, 0.8, ((0.6, 0.62, 0.8 - T), (0.6, T, 0.4)))
    movers = (_drawer("chest_drawer_l", T, 0.6 - T / 2, 0.62, 0.8 - T, 0.42, 0.4)
              + _drawer("chest_drawer_r", 0.6 + T / 2, 1.2 - T, 0.62, 0.8 - T, 0.42, 0.4)
              + _drawer("chest_drawer_wide", T, 1.2 - T, 0.4, 0.62, 0.42, 0.4)
              + _door("chest_door_l", T, 0.6 - T / 2, T, 0.4, "left") + _door("chest_door_r", 0.6 + T / 2, 1.2 - T, T, 0.4, "right"))
    body += _carcass(1.7, 0.6, TALL_DEPTH, 2.1)
    movers += (_drawer("tall_drawer_1", 1.7 + T, 2.3 - T, T, 0.28, 0.5, 0.45)
               + _drawer("tall_drawer_2", 1.7 + T, 2.3 - T, 0.28, 0.55, 0.5, 0.45)
               + _door("tall_door", 1.7 + T, 2.3 - T, 0.55, 2.1 - T, "left"))
    body += _carcass(2.8, 0.6, 0.56, 0.85)
    body.append(_box((0.02, 1.4, 2.0), (WALL_X - 0.01, 0.56 - 0.7, 1.0)))
    movers += _door("wall_door", 2.8 + T, 3.4 - T, T, 0.85 - T, "left")
    return ('<?xml version="1.0"?><robot name="cabinets"><link name="world"/>'
            f'<link name="body">{"".join(body)}</link>'
            '<joint name="fix" type="fixed"><parent link="world"/><child link="body"/></joint>'
            f'{movers}</robot>\n')


@pytest.mark.slow
def test_drawers_stay_drawers_within_their_body_and_doors_stop_at_the_wall(tmp_path: Path) -> None:
    import json

    from react3d_core.data.mesh import load_mesh
    from react3d_core.data.parts import InteractiveScene, load_vertex_ids
    from react3d_core.ground_truth import read_articulate3d
    from react3d_core.pipeline.convert import convert
    from react3d_core.synthetic import generate_scene

    urdf = tmp_path / "cabinets.urdf"
    urdf.write_text(cabinets_urdf())
    scene = generate_scene(tmp_path / "scene", source="urdf", urdf_path=urdf, n_frames=40, seed=0)
    offset = np.array(json.loads((scene / "synth_meta.json").read_text())["offset"])
    out = tmp_path / "out"
    convert(scene, out, {"perception": {"backend": "oracle"}, "frames": {"stride": 1}, "export": {"formats": []}})
    m = InteractiveScene.load(out / "scene.json")
    gt = read_articulate3d(scene / "articulate3d")
    sets, by_id = gt.movable_vertex_sets(), {p.part_id: p for p in gt.movable}
    # GT labels are '<parent>.<kind>_<k>' with k the joint's place in the URDF
    name_of = {pid: JOINTS[int(p.label.rsplit("_", 1)[1]) - 1] for pid, p in by_id.items()}
    seen: dict[str, object] = {}
    for o in m.objects:
        ids = load_vertex_ids(out / o.source_vertex_ids)
        iou = {pid: len(np.intersect1d(ids, s)) / len(np.union1d(ids, s)) for pid, s in sets.items()}
        pid = max(iou, key=iou.get)
        if iou[pid] > 0.3 and by_id[pid].articulation.joint_type == o.articulation.joint_type:
            seen[name_of[pid]] = o
    drawers = [k for k in seen if "drawer" in k]
    assert len(drawers) >= 4 and "wall_door" in seen, sorted(seen)
    for k in drawers:
        a, n = seen[k].articulation, np.asarray(seen[k].front_normal)
        off = np.degrees(np.arccos(min(1.0, abs(float(np.dot(a.axis, n))))))
        assert off <= 10.0, (k, a.axis, n)  # pulled out of its front, not slid along it
        assert float(np.dot(a.axis, [0, -1.0, 0])) > np.cos(np.radians(10.0)), (k, a.axis)
        body = TALL_DEPTH if k.startswith("tall") else CHEST_DEPTH
        assert 0.2 <= a.upper <= body, (k, a.upper, a.limit_source)  # never out of the back of its body
    # the wall door stops where it meets the wall (free it would reach the 110 deg cap): at its upper limit
    # it reaches at most 1 cm (the physics check's tolerance) past the wall's face. Only the corner at the
    # hinge, which swings back under the front plane where the sweep takes what it meets for the part's
    # own jamb, comes near that: the fitted hinge lies on the slab's mid-surface 5 mm from the wall
    door = seen["wall_door"]
    pts = load_mesh(out / door.part_mesh).vertices
    opened = door.articulation.move(pts, door.articulation.upper)
    assert door.articulation.limit_source == "sweep" and np.radians(45) < door.articulation.upper < np.radians(100)
    assert opened[:, 0].min() >= WALL_X + offset[0] - 0.01, (opened[:, 0].min(), door.articulation.upper)
