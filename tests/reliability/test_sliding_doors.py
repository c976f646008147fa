"""Acceptance: a synthetic room with sliding doors, converted by the CLI with oracle perception
(GT says "sliding") and with the heuristic (two fronts a track apart), ends with each sliding door's URDF
joint moving in the front plane (the GT axis, sign included) and the drawers of the same room still
pulled out of their fronts."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from react3d_core.data.parts import InteractiveScene, load_vertex_ids
from react3d_core.ground_truth import read_articulate3d

from .conftest import convert_oracle_urdf, run_cli


def _urdf_joints(urdf: Path) -> dict[str, tuple[str, np.ndarray, float]]:
    """joint name -> (type, axis, upper) of the movable joints."""
    out = {}
    for j in ET.parse(urdf).getroot().iter("joint"):
        if j.get("type") in ("prismatic", "revolute"):
            axis = np.array([float(x) for x in j.find("axis").get("xyz").split()])
            out[j.get("name")] = (j.get("type"), axis / np.linalg.norm(axis), float(j.find("limit").get("upper")))
    return out


@pytest.mark.parametrize("perception", ["oracle", pytest.param("heuristic", marks=pytest.mark.slow)])  # heuristic: ~2 min
def test_sliding_doors_slide_in_the_front_plane(perception: str, synthetic_scene: Callable[..., Path],
                                                 cli_env: dict[str, str], tmp_path: Path) -> None:
    scene = synthetic_scene(seed=0, n_frames=40, kind="sliding")
    out = tmp_path / "out"
    if perception == "oracle":
        r = convert_oracle_urdf(scene, out, cli_env)
    else:
        r = run_cli(["convert", str(scene), "--out", str(out), "--perception", "heuristic", "--stride", "2",
                     "--formats", "urdf"], cli_env, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    manifest = InteractiveScene.load(out)
    joints = _urdf_joints(out / manifest.exports["urdf"])
    gt = read_articulate3d(scene / "articulate3d")
    gt_sets = gt.movable_vertex_sets()
    by_id = {p.part_id: p for p in gt.movable}
    sliding = {pid for pid, p in by_id.items() if "sliding_door" in p.label}
    drawers = {pid for pid, p in by_id.items() if ".drawer" in p.label}
    assert len(sliding) == 4 and drawers  # the sideboard's and the wardrobe's pairs, the dresser's drawers
    found: dict[int, np.ndarray] = {}
    for obj in manifest.objects:
        ids = load_vertex_ids(out / obj.source_vertex_ids)
        iou = {pid: len(np.intersect1d(ids, s)) / len(np.union1d(ids, s)) for pid, s in gt_sets.items()}
        pid = max(iou, key=iou.get)
        if iou[pid] > 0.5:
            jt, axis, upper = joints[f"{obj.object_id}_joint"]
            assert jt == "prismatic", by_id[pid].label
            found[pid] = axis
            if pid in sliding:
                assert upper > 0.3  # it travels along its width (0.6-0.8 m doors), not a drawer's depth
                assert obj.inner_mesh is None  # no drawer box behind a sliding door
    assert sliding <= set(found), f"sliding doors found: {sorted(sliding & set(found))} of {sorted(sliding)}"
    for pid, axis in found.items():
        gt_axis = np.asarray(by_id[pid].articulation.axis)
        # sign included: each door slides towards the other one, not out through the carcass side
        assert float(axis @ gt_axis) > np.cos(np.radians(2.0)), (by_id[pid].label, axis, gt_axis)
