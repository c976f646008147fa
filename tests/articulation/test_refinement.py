"""Hand-computed checks of the paper's refinement formulas, the thin-slab OBB, validation and lifting."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.articulation.obb import min_obb
from react3d_core.articulation.refine import is_flat, refine_prismatic, refine_revolute, slab_mid_and_thickness
from react3d_core.articulation.validate import lift_prediction, mask_iou, snap_into_mask
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.masks import ArticulationPrediction
from react3d_core.data.parts import OBB, Articulation


def slab(w=0.6, h=0.8, t=0.02, n=2000, seed=0) -> np.ndarray:  # noqa: ANN001
    """Points on a door slab: x in [0, w], z in [0, h], y in [0, t] (front face y = 0)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform([0, 0, 0], [w, t, h], (n, 3))
    p[: n // 2, 1] = 0.0
    p[n // 2:, 1] = t
    return p


def test_obb_of_thin_slab() -> None:
    R = np.array([[np.cos(0.3), -np.sin(0.3), 0], [np.sin(0.3), np.cos(0.3), 0], [0, 0, 1]])
    pts = slab() @ R.T + [1.0, 2.0, 0.5]
    obb = min_obb(pts)
    np.testing.assert_allclose(obb.extents, [0.8, 0.6, 0.02], atol=2e-3)
    assert abs(np.dot(obb.R[:, 2], R @ [0, 1, 0])) == pytest.approx(1.0, abs=1e-5)  # < 0.3 deg
    assert abs(obb.R[:, 0][2]) == pytest.approx(1.0, abs=1e-3)  # the longest side is vertical
    assert np.linalg.det(obb.R) == pytest.approx(1.0)
    assert is_flat(obb, 0.5)
    # perfectly planar points (zero thickness) and a single point do not crash
    flat = min_obb(slab(t=0.0))
    assert flat.extents[2] == pytest.approx(0.0, abs=1e-9)
    assert min_obb(np.zeros((1, 3))).extents == (0.0, 0.0, 0.0)


def test_obb_of_door_with_handle_is_not_tilted() -> None:
    """A bar handle (4 cm proud, near one edge) tilts the PCA normal; the minimal-volume box must not."""
    door = slab(n=1000)
    zs = np.linspace(0.3, 0.5, 40)
    handle = np.concatenate([np.stack([np.full(40, 0.55), np.full(40, -0.04), zs], 1),
                             np.stack([np.full(40, 0.57), np.full(40, -0.04), zs], 1)])
    pca_n = np.linalg.svd(np.concatenate([door, handle]) - np.concatenate([door, handle]).mean(0))[2][2]
    assert np.degrees(np.arccos(abs(pca_n[1]))) > 0.5  # PCA alone is off by more than half a degree
    obb = min_obb(np.concatenate([door, handle]))
    assert abs(obb.R[:, 2][1]) == pytest.approx(1.0, abs=1e-6)  # box normal = y exactly
    np.testing.assert_allclose(obb.extents, [0.8, 0.6, 0.06], atol=2e-3)  # thickness 0.02 + 0.04 handle


def _door_obb() -> OBB:
    # u1 = z (0.8 tall), u2 = x (0.6 wide), u3 = y (0.02 thick); centre of the slab
    return OBB(center=(0.3, 0.01, 0.4), axes=((0, 0, 1.0), (1.0, 0, 0), (0, 1.0, 0)), extents=(0.8, 0.6, 0.02))


def test_prismatic_sign_follows_prediction() -> None:
    n = np.array([0.0, 1.0, 0.0])
    a = Articulation(joint_type="prismatic", axis=(0.1, -0.99, 0.05), origin=(0, 0, 0))
    r = refine_prismatic(a, n)
    np.testing.assert_allclose(r.axis, [0, -1, 0], atol=1e-12)  # sign(<a, n>) n with <a, n> < 0
    assert r.origin == a.origin
    b = refine_prismatic(a.model_copy(update={"axis": (0.2, 0.9, 0.0)}), n)
    np.testing.assert_allclose(b.axis, [0, 1, 0], atol=1e-12)


def test_revolute_edge_choice_and_mid_surface_origin() -> None:
    obb = _door_obb()
    mid = np.array([0.3, 0.01, 0.4])
    # predicted: nearly vertical, pointing down, 7 cm left of the x = 0 edge
    a = Articulation(joint_type="revolute", axis=(0.05, 0.0, -0.99), origin=(-0.07, -0.2, 0.4))
    r = refine_revolute(a, obb, mid)
    np.testing.assert_allclose(r.axis, [0, 0, -1], atol=1e-12)       # l = u1 (z), signed like the prediction
    np.testing.assert_allclose(r.origin, [0.0, 0.01, 0.4], atol=1e-12)  # x = 0 edge, mid-surface y = t/2
    # predicted near the other edge -> the x = 0.6 edge
    r2 = refine_revolute(a.model_copy(update={"origin": (0.65, 0.3, 0.1)}), obb, mid)
    np.testing.assert_allclose(r2.origin, [0.6, 0.01, 0.4], atol=1e-12)
    # a horizontal prediction picks the horizontal edge direction (top-hinged flap)
    r3 = refine_revolute(Articulation(joint_type="revolute", axis=(1.0, 0.0, 0.1), origin=(0.3, 0.0, 0.85)), obb, mid)
    np.testing.assert_allclose(r3.axis, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(r3.origin, [0.3, 0.01, 0.8], atol=1e-12)


def test_slab_mid_surface_ignores_a_handle() -> None:
    pts = slab(t=0.02)
    handle = np.random.default_rng(1).uniform([0.5, -0.04, 0.3], [0.52, 0.0, 0.45], (150, 3))
    mid, t = slab_mid_and_thickness(np.concatenate([pts, handle]), np.array([0.3, 0.0, 0.4]), np.array([0.0, 1.0, 0.0]))
    assert mid[1] == pytest.approx(0.01, abs=1e-9) and t == pytest.approx(0.02, abs=1e-9)


def test_mask_iou_and_snap() -> None:
    a = np.zeros((4, 4), bool)
    a[:2, :2] = True
    b = np.zeros((4, 4), bool)
    b[:2, :] = True
    assert mask_iou(a, b) == pytest.approx(4 / 8)
    assert snap_into_mask((3.2, 3.0), a) == (1, 1)
    assert snap_into_mask((0.4, 0.6), a) == (0, 1)


def test_lift_prediction_to_world_hand_computed(tmp_path) -> None:  # noqa: ANN001
    c2w = np.eye(4)
    c2w[:3, :3] = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]  # camera looks along +x, image x -> world -y
    c2w[:3, 3] = [1, 2, 3]
    img = tmp_path / "f.png"
    img.write_bytes(b"")
    f = Frame(frame_id="f", rgb=ImageRef(path=img, kind="png"), pose=c2w.tolist(),
              intrinsics=Intrinsics(fx=100, fy=100, cx=2, cy=2, width=4, height=4))
    mask = np.ones((4, 4), bool)
    p = ArticulationPrediction(frame_id="f", mask=mask, joint_type="revolute", axis_cam=(0, -1, 0), origin_px=(3, 2))
    depth = np.full((4, 4), 2.0)
    a = lift_prediction(p, f, depth)
    np.testing.assert_allclose(a.axis, [0, 0, 1], atol=1e-12)  # camera up (-y) is world +z
    # pixel (3, 2) at 2 m: camera point (0.02, 0, 2) -> world (1 + 2, 2 - 0.02, 3)
    np.testing.assert_allclose(a.origin, [3.0, 1.98, 3.0], atol=1e-12)


def test_consensus_joint_takes_the_median_origin_and_the_mean_axis_of_the_views() -> None:
    from react3d_core.articulation.validate import consensus_joint

    def rev(o, a) -> Articulation:  # noqa: ANN001
        return Articulation(joint_type="revolute", axis=a, origin=o, lower=0.0, upper=0.0, limit_source="unset")

    best = rev((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    others = [rev((1.0, 0.0, 0.0), (0.0, 0.0, -1.0)), rev((0.2, 0.4, 0.0), (0.0, 0.0, 1.0)),
              rev((0.1, 0.0, 2.0), (0.0, 0.0, -1.0)),
              Articulation(joint_type="prismatic", axis=(1.0, 0, 0), origin=(9.0, 9.0, 9.0), lower=0.0, upper=0.0,
                           limit_source="unset")]  # another joint type does not vote
    out = consensus_joint(best, others)
    # x: median(0, 1, 0.2, 0.1) = 0.15; y: median(0, 0, 0.4, 0) = 0; z: median(0, 0, 0, 2) = 0
    assert np.allclose(out.origin, (0.15, 0.0, 0.0))
    assert np.allclose(out.axis, (0.0, 0.0, 1.0))  # flipped axes are aligned to the best view's before averaging
    assert out.joint_type == "revolute" and consensus_joint(best, []) == best


def test_vertical_fronts_keep_an_upright_box_unless_the_minimal_one_is_clearly_smaller() -> None:
    from react3d_core.articulation.upright import upright_box

    rng = np.random.default_rng(0)
    # a 0.40 x 0.70 m door in the x-z plane (normal y), segmented 6 cm sheared (a parallelogram): its
    # minimal box leans 4.9 degrees and is 7.8 % smaller than the upright one
    u, z = rng.uniform(0, 0.4, 3000), rng.uniform(0, 0.7, 3000)
    door = np.c_[u, rng.uniform(0, 0.02, 3000), z]
    pts = np.c_[u + 0.06 * z / 0.7, door[:, 1], z]
    m = min_obb(pts)
    tilt = np.degrees(np.arccos(min(1.0, abs(m.R[:, 0] @ [0, 0, 1.0]))))
    assert 4.0 < tilt < 6.0
    up = upright_box(pts, m, 0.1)
    assert np.allclose(np.abs(up.R[:, 0]), [0, 0, 1]) and np.allclose(np.abs(up.R[:, 2]), [0, 1, 0])
    assert np.allclose(up.extents, (0.7, 0.46, 0.02), atol=6e-3)  # random samples reach 0.455 of 0.46
    assert upright_box(pts, m, 0.05) == m  # the upright box is 7.8 % larger: beyond a 5 % tolerance
    assert upright_box(pts, m, 0.0) == m  # tolerance 0: the paper's minimal box

    # a front that really leans (30 degrees in its plane): the upright box is far larger, the minimal box stays
    t = np.radians(30)
    rot = np.array([[np.cos(t), 0, -np.sin(t)], [0, 1, 0], [np.sin(t), 0, np.cos(t)]])
    leaning = door @ rot.T
    m2 = min_obb(leaning)
    assert upright_box(leaning, m2, 0.1) == m2
    # a horizontal part (a drawer bottom, normal z) is not a vertical front
    flat = door[:, [0, 2, 1]]
    m3 = min_obb(flat)
    assert upright_box(flat, m3, 0.1) == m3
