"""The 2D bench's matching and GT masks, on hand-computed cases."""

from __future__ import annotations

import numpy as np

from benchmarks.bench_masks import gt_openable_masks, match


def test_match_one_to_one_hand_computed() -> None:
    a = np.zeros((4, 4), bool); a[:2, :2] = True          # 4 px
    b = np.zeros((4, 4), bool); b[:2, :3] = True          # 6 px: IoU(a, b) = 4/6
    c = np.zeros((4, 4), bool); c[3, :] = True            # disjoint
    pairs = match([a, c], [b, a])
    assert [(i, j) for i, j, _ in pairs] == [(0, 1)]       # a -> a (IoU 1), c matches nothing
    assert pairs[0][2] == 1.0
    assert [(i, j, round(v, 4)) for i, j, v in match([a], [b])] == [(0, 0, 0.6667)]
    assert match([a], [b], thr=0.7) == [] and match([], [b]) == []


def test_gt_masks_include_handles_and_skip_fixed_parts() -> None:
    ids = np.array([[1, 1, 3], [2, 0, 3]])
    meta = {"parts": [{"part_id": 0, "type": "revolute", "handle_part_id": 2},
                      {"part_id": 1, "type": "fixed"}, {"part_id": 2, "type": "fixed"}]}
    gt = gt_openable_masks(ids, meta)
    assert list(gt) == [0] and gt[0][1] == "revolute"
    assert gt[0][0].tolist() == [[True, True, True], [False, False, True]]
