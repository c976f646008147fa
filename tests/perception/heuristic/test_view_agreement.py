"""Fronts found again on interleaved subsets of the frames (``agreement``): hand-computed overlaps, and the
real heuristic on a generated dresser, with and without the test."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.perception.heuristic import HeuristicModel
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.view_agreement import (agreement, holds, interleaved_subsets, kept_by_agreement,
                                                              rect_iou, same_plane)
from react3d_core.scene_io import load_scene


def _front(center: tuple[float, float, float], w: float, h: float, n: tuple[float, float, float] = (0.0, -1.0, 0.0),
           u: tuple[float, float, float] = (1.0, 0.0, 0.0), u0: float = 0.0) -> Front:
    """A front centred at ``center``; ``u0`` shifts its extent pair (its axis origin) without moving it."""
    return Front(facet=-1, handle_facets=[], center=np.array(center), n_out=np.array(n), u=np.array(u),
                 extent_u=(u0, u0 + w), extent_v=(center[2] - h / 2, center[2] + h / 2))


def test_subsets_deal_every_kth_frame() -> None:
    subs = interleaved_subsets(7, 3)
    assert [s.tolist() for s in subs] == [[0, 3, 6], [1, 4], [2, 5]]
    with pytest.raises(ValueError):
        interleaved_subsets(7, 0)


def test_rect_iou_hand_computed() -> None:
    f = _front((0.0, 0.0, 1.0), 0.6, 0.8)
    g = _front((0.3, 0.0, 1.2), 0.6, 0.8)
    # overlap 0.3 x 0.6 = 0.18; union 0.48 + 0.48 - 0.18 = 0.78
    assert rect_iou(f, g) == pytest.approx(0.18 / 0.78)
    assert rect_iou(g, f) == pytest.approx(0.18 / 0.78)
    # the same rectangle with its axis the other way and another extent origin
    g2 = _front((0.3, 0.0, 1.2), 0.6, 0.8, u=(-1.0, 0.0, 0.0), u0=-5.0)
    assert rect_iou(f, g2) == pytest.approx(0.18 / 0.78)
    # one inside the other: IoU is the area ratio (0.3 x 0.4 of 0.6 x 0.8)
    assert rect_iou(f, _front((0.1, 0.0, 1.1), 0.3, 0.4)) == pytest.approx(0.12 / 0.48)
    assert rect_iou(f, _front((0.7, 0.0, 1.0), 0.6, 0.8)) == 0.0  # side by side, touching at most


def test_same_plane_needs_normal_and_depth() -> None:
    f = _front((0.0, 0.0, 1.0), 0.6, 0.8)
    assert same_plane(f, _front((0.2, 0.03, 1.0), 0.6, 0.8), 0.94, 0.05)
    assert not same_plane(f, _front((0.2, 0.1, 1.0), 0.6, 0.8), 0.94, 0.05)  # 10 cm behind
    a = np.radians(30)
    turned = _front((0.0, 0.0, 1.0), 0.6, 0.8, n=(np.sin(a), -np.cos(a), 0.0), u=(np.cos(a), np.sin(a), 0.0))
    assert not same_plane(f, turned, 0.94, 0.05)  # cos 30 deg = 0.866


def test_agreement_counts_runs_holding_a_front() -> None:
    f = _front((0.0, 0.0, 1.0), 0.6, 0.8)
    near = _front((0.1, 0.0, 1.0), 0.6, 0.8)        # IoU 0.40 / 0.56 = 0.714
    shifted = _front((0.4, 0.0, 1.0), 0.6, 0.8)     # IoU 0.16 / 0.80 = 0.2
    behind = _front((0.0, 0.2, 1.0), 0.6, 0.8)      # same rectangle, 20 cm behind
    runs = [[near], [shifted], [behind], [near, shifted]]
    assert holds(f, [near], 0.3, 0.94, 0.05) and not holds(f, [shifted], 0.3, 0.94, 0.05)
    assert holds(f, [shifted], 0.19, 0.94, 0.05)
    assert agreement([f], runs, 0.3, 0.94, 0.05) == [2]
    assert agreement([f, behind], runs, 0.3, 0.94, 0.05) == [2, 1]


def test_kept_by_agreement_drops_fronts_too_few_runs_hold() -> None:
    fs = [_front((x, 0.0, 1.0), 0.5, 0.7) for x in (0.0, 1.0, 2.0)]
    kept, counts = kept_by_agreement(fs, [2, 0, 1], 1)
    assert [k is f for k, f in zip(kept, (fs[0], fs[2]))] == [True, True] and counts == [2, 1]
    assert kept_by_agreement(fs, [2, 0, 1], 2) == ([fs[0]], [2])


def test_heuristic_keeps_fronts_its_subsets_find_again(synthetic_scene) -> None:  # noqa: ANN001
    scene = load_scene(synthetic_scene(seed=3, n_frames=16, kind="dresser"))
    # too few frames for three subsets of 10: no test, every front kept
    base = HeuristicModel(scene, HeuristicConfig(agreement={"subsets": 3, "min_frames": 10}))
    assert base.agreement is None and base.subset_fronts is None and len(base.fronts) >= 3
    on = HeuristicModel(scene, HeuristicConfig(agreement={"subsets": 3, "min_frames": 5}))
    assert on.subset_fronts is not None and len(on.subset_fronts) == 3
    assert [f.center.tolist() for f in on.fronts] == [f.center.tolist() for f in base.fronts]
    assert on.agreement is not None and len(on.agreement) == len(on.fronts) and min(on.agreement) >= 1
    # a front where the scan holds none: no subset finds it again
    ghost = _front((9.0, 9.0, 1.0), 0.5, 0.7)
    ag = on.config.agreement
    assert agreement([ghost], on.subset_fronts, ag.min_iou, ag.plane_cos, ag.plane_gap) == [0]
