"""Shared data model: pose validation, Articulation.move (hand-computed), masks npz and Articulate3D round trips."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.data.frames import validate_pose
from react3d_core.data.masks import Mask2D, PackedMasks, load_masks, save_masks
from react3d_core.data.parts import Articulation
from react3d_core.ground_truth.articulate3d import GroundTruth, GTPart, read_articulate3d, write_articulate3d


def test_validate_pose() -> None:
    validate_pose(np.eye(4))
    for bad, msg in ((np.full((4, 4), np.inf), "NaN"), (np.diag([1.0, 1, 1.1, 1]), "orthonormal"),
                     (np.diag([1.0, 1, -1, 1]), "reflection"), (np.eye(3), "4x4")):
        with pytest.raises(ValueError, match=msg):
            validate_pose(bad)


def test_articulation_move_hand_computed() -> None:
    # revolute about z through (1, 0, 0): point (2, 0, 0) turned 90 deg -> (1, 1, 0)
    rev = Articulation(joint_type="revolute", axis=[0, 0, 2], origin=[1, 0, 0])
    assert rev.move(np.array([[2.0, 0, 0]]), np.pi / 2)[0] == pytest.approx([1, 1, 0])
    # prismatic along x (axis normalised from (3,0,0)): 0.25 m
    pri = Articulation(joint_type="prismatic", axis=[3, 0, 0], origin=[0, 0, 0])
    assert pri.move(np.array([[0.0, 1, 2]]), 0.25)[0] == pytest.approx([0.25, 1, 2])


def test_masks_roundtrip(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    ms = [Mask2D(frame_id=f"frame_{i:06d}", label="door", score=0.5 + 0.1 * i, mask=rng.random((12, 16)) > 0.5,
                 box=(1.0, 2.0, 3.0, 4.0), instance=(None, 0, 7)[i]) for i in range(3)]
    back = load_masks(save_masks(tmp_path / "m.npz", ms))
    assert [(m.frame_id, m.label, m.score, m.box, m.instance) for m in back] == \
        [(m.frame_id, m.label, m.score, m.box, m.instance) for m in ms]
    assert all(np.array_equal(a.mask, b.mask) for a, b in zip(ms, back))


def test_packed_masks_unpack_on_access() -> None:
    rng = np.random.default_rng(0)
    a = [Mask2D(frame_id="f0", label="door", score=0.5, mask=rng.random((5, 11)) > 0.5, box=(1.0, 2.0, 3.0, 4.0),
                instance=3),
         Mask2D(frame_id="f0", mask=np.zeros((5, 11), bool))]
    pm = PackedMasks()
    pm.add("f0", a)
    pm.add("f1", [])
    assert list(pm) == ["f0", "f1"] and len(pm) == 2 and pm.get("f2") is None
    assert pm.nbytes == 2 * 7  # 55 bits -> 7 bytes per mask
    got = pm["f0"]
    assert len(got) == 2 and len(pm["f1"]) == 0
    for m, g in zip(a, [got[0], got[-1]]):
        assert g.mask.dtype == bool and np.array_equal(g.mask, m.mask)
        assert (g.frame_id, g.label, g.score, g.box, g.instance) == (m.frame_id, m.label, m.score, m.box, m.instance)
    assert [np.array_equal(g.mask, m.mask) for g, m in zip(got[0:2], a)] == [True, True]
    with pytest.raises(IndexError):
        got[2]


def test_articulate3d_roundtrip(tmp_path: Path) -> None:
    art = Articulation(joint_type="revolute", axis=[0, 0, 1], origin=[0.5, 0.2, 0], lower=0.0, upper=1.5)
    gt = GroundTruth("scn", [GTPart(1, "cabinet.door", np.array([0, 1, 2]), np.array([0, 1, 2, 3]), art),
                             GTPart(2, "cabinet.door.handle", np.array([3]), np.array([4, 5, 6]))])
    write_articulate3d(tmp_path, gt)
    back = read_articulate3d(tmp_path, "scn")
    assert len(back.movable) == 1 and back.movable[0].part_id == 1
    b = back.movable[0].articulation
    assert b.joint_type == "revolute" and np.abs(np.abs(np.dot(b.axis, art.axis)) - 1) < 1e-9
    assert (b.lower, b.upper) == pytest.approx((0.0, 1.5))
    assert back.movable_vertex_sets()[1].tolist() == [0, 1, 2, 3, 4, 5, 6]
