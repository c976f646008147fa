"""Oracle perception backend on a synthetic scene: GT masks, each kind of noise, GT joints in camera frame."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from react3d_core.config import OracleNoiseConfig, PerceptionConfig
from react3d_core.perception.interfaces import ArticulationPredictor, PointPromptSegmenter, Tagger, TagFilter, TextPromptSegmenter
from react3d_core.perception.oracle import OracleModel, make_oracle
from react3d_core.scene_io import load_scene


@pytest.fixture(scope="module")
def scene(synthetic_scene):
    return load_scene(synthetic_scene(seed=3, n_frames=16, kind="dresser"))


def model(scene, **noise) -> OracleModel:
    base = {"boundary_px": 0, "drop_rate": 0.0, "axis_noise_deg": 0.0, "origin_noise_m": 0.0}
    return OracleModel(scene, OracleNoiseConfig(**{**base, **noise}))


def _frame_with_parts(m: OracleModel, scene, n: int = 2):
    for f in scene.frames:
        if len(m.visible_movable(m.part_image(f))) >= n:
            return f
    raise AssertionError("no frame sees enough parts")


def test_backend_implements_the_protocols(scene):
    p = make_oracle(scene, PerceptionConfig(backend="oracle"))
    assert isinstance(p.tagger, Tagger) and isinstance(p.tag_filter, TagFilter)
    assert isinstance(p.segmenter, TextPromptSegmenter) and isinstance(p.point_segmenter, PointPromptSegmenter)
    assert isinstance(p.articulation, ArticulationPredictor) and p.name == "oracle"
    tags = p.tagger.tag(scene.frames[:3], [None] * 3)
    assert any("drawer" in t or "door" in t for t in tags[0])
    assert p.tag_filter.filter(["a", "b"]) == ["a", "b"]


def test_clean_masks_are_the_gt_parts_with_handles(scene):
    m = model(scene)
    f = _frame_with_parts(m, scene)
    img = m.part_image(f)
    vis = m.visible_movable(img)
    masks = m.masks(f)
    assert len(masks) == len(vis)
    for mk, (pid, reg) in zip(masks, vis):
        assert np.array_equal(mk.mask, reg) and reg.sum() >= 100
        assert mk.box is not None and mk.mask.shape == (f.intrinsics.height, f.intrinsics.width)
    assert all(pid in m.movable for pid, _ in vis)  # static parts (carcass, handles) are never masks


def test_masks_are_deterministic_and_seeded(scene):
    a = model(scene, drop_rate=0.5, seed=1)
    b = model(scene, drop_rate=0.5, seed=1)
    c = model(scene, drop_rate=0.5, seed=2)
    fa = [len(a.masks(f)) for f in scene.frames]
    assert fa == [len(b.masks(f)) for f in scene.frames]
    assert fa != [len(c.masks(f)) for f in scene.frames]


def test_drops_handle_holes_boundary_whole_object_false_positives(scene):
    clean = model(scene)
    f = _frame_with_parts(clean, scene)
    img = clean.part_image(f)
    assert model(scene, drop_rate=1.0).masks(f) == [] and model(scene, drop_rate=1.0).predictions(f) == []
    pid, reg = next((p, r) for p, r in clean.visible_movable(img) if clean.handles[p] and np.isin(img, clean.handles[p]).any())
    handle_px = np.isin(img, clean.handles[pid])
    holes = model(scene, handle_holes=True)
    mk = next(x for x in holes.masks(f) if (x.mask & reg).sum() > 0.5 * reg.sum())
    assert not (mk.mask & handle_px).any() and (mk.mask | handle_px).sum() == reg.sum()
    dil = model(scene, boundary_px=2)  # 2 px at 960 px width
    mk = next(x for x in dil.masks(f) if (x.mask & reg).sum() == reg.sum())
    r = round(2 * img.shape[1] / 960)
    expect = cv2.dilate(reg.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))).astype(bool)
    assert np.array_equal(mk.mask, expect)
    whole = model(scene, whole_object_rate=1.0)
    base = np.isin(img, whole.parts[pid].base)
    mk = next(x for x in whole.masks(f) if (x.mask & reg).sum() == reg.sum())
    assert base.any() and np.array_equal(mk.mask, reg | base)
    fp = model(scene, false_positive_rate=3.0)
    n_fp = sum(len(fp.masks(g)) - len(clean.masks(g)) for g in scene.frames)
    assert 0.4 * 3 * len(scene.frames) < n_fp < 1.6 * 3 * len(scene.frames)


def test_merged_neighbours(scene):
    clean = model(scene)
    merged = model(scene, merge_rate=1.0)
    n_clean = sum(len(clean.masks(f)) for f in scene.frames)
    n_merged = sum(len(merged.masks(f)) for f in scene.frames)
    assert n_merged < n_clean  # adjacent drawers come out as one mask
    assert sum(x.area for f in scene.frames for x in merged.masks(f)) == sum(x.area for f in scene.frames for x in clean.masks(f))


def test_point_prompts_answer_the_part_under_the_points(scene):
    m = model(scene)
    f = _frame_with_parts(m, scene)
    img = m.part_image(f)
    pid, reg = next((p, r) for p, r in m.visible_movable(img) if np.isin(img, m.handles[p]).any())
    hy, hx = np.nonzero(np.isin(img, m.handles[pid]))
    out = m.point_mask(f, np.array([[hx[0], hy[0]], [5, 5]], float), np.array([1, 0]))  # a click on the handle
    assert np.array_equal(out.mask, reg)
    ys, xs = np.nonzero(img == pid)
    pts = np.array([[xs[0], ys[0]], [xs[-1], ys[-1]], [0, 0]], float)
    assert np.array_equal(m.point_mask(f, pts, np.array([1, 1, 1])).mask, reg)  # majority wins
    empty = m.point_mask(f, np.zeros((0, 2)), np.zeros(0))
    assert empty.area == 0 and empty.score == 0


def test_predictions_are_gt_joints_in_the_camera_frame(scene):
    m = model(scene)
    f = _frame_with_parts(m, scene)
    preds = m.predictions(f)
    assert preds
    R, t = f.w2c[:3, :3], f.w2c[:3, 3]
    for pr in preds:
        pid = next(p for p, r in m.visible_movable(m.part_image(f)) if np.array_equal(r, pr.mask))
        art = m.parts[pid].articulation
        assert pr.joint_type == art.joint_type
        assert np.allclose(pr.axis_cam, R @ np.asarray(art.axis), atol=1e-9)
        assert np.allclose(pr.origin_cam, R @ np.asarray(art.origin) + t, atol=1e-9)
    flip = model(scene, type_flip_rate=1.0).predictions(f)
    assert all(a.joint_type != b.joint_type for a, b in zip(preds, flip))
    noisy = model(scene, axis_noise_deg=7.0, origin_noise_m=0.2)
    ang, dist = [], []
    for g in scene.frames:
        for a, b in zip(m.predictions(g), noisy.predictions(g)):
            ang.append(np.degrees(np.arccos(np.clip(np.dot(a.axis_cam, b.axis_cam), -1, 1))))
            dist.append(np.linalg.norm(np.subtract(a.origin_cam, b.origin_cam)))
    assert 2 < np.mean(ang) < 12 and 0.08 < np.mean(dist) < 0.35  # |N(0,7 deg)| ~ 5.6; rms 0.2 m -> mean ~0.18


def test_without_part_id_images_the_gt_faces_are_rendered(scene):
    m = model(scene)
    f = _frame_with_parts(m, scene)
    bare = scene.model_copy(update={"frames": tuple(g.model_copy(update={"part_ids": None}) for g in scene.frames)})
    r = model(bare)
    a, b = m.part_image(f), r.part_image(bare.frame(f.frame_id))
    assert (a == b).mean() > 0.97
