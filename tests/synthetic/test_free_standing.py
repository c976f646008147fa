"""Rooms of free-standing furniture and appliances: determinism, joints, GT against the rendered ids,
glass seen through in colour and depth, depth dropped on dark surfaces only."""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np
import pytest

from react3d_core.data.mesh import load_mesh
from react3d_core.ground_truth import read_articulate3d
from react3d_core.raster import Rasterizer
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_depth, read_label_image
from react3d_core.synthetic import generate_scene
from react3d_core.synthetic.depth_effects import dark_dropout, linear_albedo
from react3d_core.synthetic.materials import GLASS
from react3d_core.synthetic.procedural import build_room
from react3d_core.synthetic.render import DEPTH_SIZE, RayCaster, base_intrinsics, scale_K
from react3d_core.synthetic.rooms import FREE_KINDS

GLASS_SCENE = {"seed": 0, "n_frames": 3, "kind": "glass"}


def _hashes(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and p.name != "synth_meta.json" and "articulate3d" not in str(p)}


@pytest.mark.parametrize("kind", FREE_KINDS)
def test_layout_is_deterministic_and_outside_the_seed_rotation(kind: str) -> None:
    from react3d_core.synthetic import KINDS

    t0 = time.perf_counter()
    a, b = build_room(3, kind), build_room(3, kind)
    assert time.perf_counter() - t0 < 10.0  # two layouts: a fraction of a second each on an idle machine
    assert kind not in KINDS and a.kind == kind and a.gt_boxes
    assert np.array_equal(a.mesh.vertices, b.mesh.vertices) and np.array_equal(a.mesh.faces, b.mesh.faces)
    assert np.array_equal(a.face_keys, b.face_keys) and np.array_equal(a.face_materials, b.face_materials)
    assert [(p.label, p.articulation) for p in a.parts] == [(p.label, p.articulation) for p in b.parts]
    assert build_room(4, kind).mesh.n_faces != a.mesh.n_faces


def _part_points(layout, key: str) -> np.ndarray:  # noqa: ANN001
    return layout.mesh.vertices[np.unique(layout.mesh.faces[layout.face_keys == layout.key_ids[key]].ravel())]


@pytest.mark.parametrize("kind", FREE_KINDS)
def test_joints_open_out_of_their_body_along_the_box(kind: str) -> None:
    """Every front opens out of its own body (its centre moves out along its box's thin side, away from
    the body's centre), prismatic parts slide along that side, hinges lie on an edge of the part's box
    along one of its sides; limits > 0."""
    from react3d_core.synthetic.writer import part_box

    n_parts, kinds = 0, set()
    for seed in range(6):
        layout = build_room(seed, kind)
        assert layout.parts and 20_000 <= layout.mesh.n_faces <= 300_000
        for p in layout.parts:
            a = p.articulation
            assert a.lower == 0.0 < a.upper, p.label
            pts = _part_points(layout, p.key)
            body = _part_points(layout, p.parent_key)
            centre = 0.5 * (body.min(0) + body.max(0))
            c0 = pts.mean(0)
            moved = a.move(pts, 0.5 * a.upper).mean(0)
            box = part_box(pts)
            R, ext = box.R, np.asarray(box.extents)
            out = R[:, 2] * np.sign(R[:, 2] @ (c0 - centre))
            assert (moved - c0) @ out > 0.02, p.label
            ax = np.asarray(a.axis)
            if a.joint_type == "prismatic":
                assert abs(ax @ R[:, 2]) > 0.999, p.label  # drawers slide along the front's normal
            else:
                k = int(np.argmax(np.abs(R.T @ ax)))
                assert abs(ax @ R[:, k]) > 0.999, p.label
                assert k != 2 or p.kind == "lid" or ext[1] - ext[2] < 0.02, p.label  # hinge along the front, not its normal
                local = R.T @ (np.asarray(a.origin) - np.asarray(box.center))
                others = [j for j in range(3) if j != k]
                on_edge = max(abs(abs(local[j]) - ext[j] / 2) for j in others if ext[j] > 0.1)
                assert on_edge < 0.04, (p.label, local, ext)
            n_parts += 1
            kinds.add(p.kind)
    assert n_parts >= 40
    if kind == "appliances":
        assert {"door", "drawer", "drop", "lid"} <= kinds
    if kind == "furniture":
        assert {"door", "drawer"} <= kinds


def test_drawer_fronts_from_ten_centimetres_and_pieces_free_in_the_room() -> None:
    heights, free, turned = [], 0, 0
    for seed in range(12):
        layout = build_room(seed, "furniture")
        for p in layout.parts:
            if p.kind == "drawer":
                pts = _part_points(layout, p.key)
                heights.append(pts[:, 2].max() - pts[:, 2].min())
        W, L, _ = layout.room
        for r in layout.runs:
            back = r.frame.T[:2, 3]
            if min(back[0], back[1], W - back[0], L - back[1]) > 0.5:
                free += 1
                turned += abs(np.sin(2 * r.frame.theta)) > 0.05
    assert min(heights) < 0.12 and max(heights) > 0.3
    assert free >= 4 and turned >= 1


def test_round_door_lid_and_glass_are_one_part() -> None:
    found = set()
    for seed in range(12):
        layout = build_room(seed, "appliances")
        for p in layout.parts:
            faces = layout.face_keys == layout.key_ids[p.key]
            if p.label.startswith("washing_machine") and p.kind == "door":
                pts = _part_points(layout, p.key)
                ext = pts.max(0) - pts.min(0)
                assert np.sort(ext)[-1] == pytest.approx(np.sort(ext)[-2], abs=0.01)  # round: as wide as high
                assert (layout.face_materials[faces] == GLASS).any()
                found.add("porthole")
            if p.kind == "lid":
                assert abs(p.articulation.axis[2]) < 1e-9
                found.add("lid")
    assert found == {"porthole", "lid"}


def test_same_seed_same_bytes_with_glass_tsdf_and_dropout(tmp_path: Path) -> None:
    opts = {"seed": 1, "n_frames": 2, "kind": "dark", "mesh": "tsdf", "depth_dropout": "dark"}
    a = generate_scene(tmp_path / "a", **opts)
    b = generate_scene(tmp_path / "b", **opts)
    assert _hashes(a) == _hashes(b) and len(_hashes(a)) == 1 + 1 + 2 + 2 + 1
    meta = json.loads((a / "synth_meta.json").read_text())
    assert meta["depth_dropout"] == "dark" and all("scan_coverage" in r for r in meta["parts"])
    gt = read_articulate3d(a / "articulate3d")
    assert all(p.obb is not None and p.coverage is not None for p in gt.movable)
    assert len(gt.movable) == len(build_room(1, "dark").parts)  # parts without scan surface are kept


def test_glass_scene_gt_matches_rendered_ids_and_the_scan_lacks_glass(synthetic_scene) -> None:  # noqa: ANN001
    root = synthetic_scene(**GLASS_SCENE)
    layout = build_room(GLASS_SCENE["seed"], "glass")
    glass = layout.face_materials == GLASS
    assert glass.sum() > 100
    scene = load_scene(root)
    mesh = load_mesh(scene.mesh_path)
    assert mesh.n_faces == layout.mesh.n_faces - glass.sum()  # the written clean mesh has no glass
    gt = read_articulate3d(scene.gt_dir)
    face_pid = np.full(mesh.n_faces, -1)
    for p in gt.parts:
        assert face_pid[p.tri_indices].max() == -1
        face_pid[p.tri_indices] = p.part_id
    full = Rasterizer(layout.mesh)
    r = Rasterizer(mesh)
    n_glass_px = 0
    for f in scene.frames:
        ids = read_label_image(f.part_ids).astype(np.int64)
        res = r.render_frame(f)
        hit_glass = glass[np.maximum(full.render_frame(f).face_ids, 0)] & (full.render_frame(f).face_ids >= 0)
        expect = np.where(res.face_ids >= 0, face_pid[np.maximum(res.face_ids, 0)] + 1, 0)
        ok = ~hit_glass
        assert (expect[ok] == ids[ok]).mean() > 0.995
        # behind glass the scan shows the cabinet's inside; the GT image shows the glass door
        movable = {p.part_id + 1 for p in gt.movable}
        assert np.isin(ids[hit_glass], list(movable)).mean() > 0.99
        n_glass_px += int(hit_glass.sum())
    assert n_glass_px > 1000
    meta = json.loads((root / "synth_meta.json").read_text())
    assert meta["mesh"]["glass_faces_left_out"] == int(glass.sum())
    assert all(r["scan_coverage"] == 1.0 for r in meta["parts"])  # the clean mesh holds every opaque front


def test_glass_depth_reads_what_lies_behind(synthetic_scene) -> None:  # noqa: ANN001
    """Glass pixels of the depth frames read the surface behind the pane (a hand-checkable pixel: the
    first opaque hit of the same ray), not the pane; elsewhere the depth is the first hit."""
    root = synthetic_scene(**GLASS_SCENE)
    layout = build_room(GLASS_SCENE["seed"], "glass")
    glass = layout.face_materials == GLASS
    opaque, _ = layout.mesh.submesh(np.flatnonzero(~glass))
    full_c, back_c = RayCaster(layout.mesh), RayCaster(opaque)
    scene = load_scene(root)
    checked = 0
    for f in scene.frames:
        d = read_depth(f.depth)
        poses = json.loads((root / "iphone" / "pose_intrinsic_imu.json").read_text())[f.frame_id]
        K = scale_K(np.asarray(poses["intrinsic"]), DEPTH_SIZE[0])
        c2w = np.asarray(poses["aligned_pose"])
        fh = full_c.cast(K, c2w, *DEPTH_SIZE)
        bh = back_c.cast(K, c2w, *DEPTH_SIZE)
        g = (fh["face"] >= 0) & glass[np.maximum(fh["face"], 0)] & (d > 0)
        far = g & (bh["depth"] - fh["depth"] > 0.1)  # the pane is > 10 cm in front of what is behind it
        if far.sum() < 20:
            continue
        err_behind = np.abs(d[far] - bh["depth"][far])
        err_pane = np.abs(d[far] - fh["depth"][far])
        assert np.median(err_behind) < 0.02 and (err_behind < err_pane).mean() > 0.9
        checked += int(far.sum())
        ng = (fh["face"] >= 0) & ~glass[np.maximum(fh["face"], 0)] & (d > 0)
        assert np.median(np.abs(d[ng] - fh["depth"][ng])) < 0.01
    assert checked > 100


def test_through_glass_by_hand() -> None:
    """One pixel seen head-on through a pane, no lights: out = behind x tint x (1 - F0) + refl x F0 x (0.45 + 0.35 rz)."""
    from react3d_core.synthetic.materials import _SPEC, GlassLayer, PhotoSettings, _through_glass

    img = np.full((1, 1, 3), 0.5, np.float32)
    d = np.array([0.0, 1.0, 0.0], np.float32).reshape(3, 1, 1)  # looking along +y, level: rz = 0
    layer = GlassLayer(np.ones((1, 1), bool), np.array([[[0.0, -1.0, 0.0]]]), np.zeros((1, 1, 3)),
                       np.array([[[0.8, 0.9, 1.0]]], np.float32))
    out = _through_glass(img, layer, d, PhotoSettings(np.zeros((0, 4), np.float32)))
    f0, refl = float(_SPEC[GLASS, 4]), float(_SPEC[GLASS, 5])
    assert (f0, refl) == pytest.approx((0.06, 1.0))
    expect = 0.5 * np.array([0.8, 0.9, 1.0]) * (1 - 0.06) + 1.0 * 0.06 * 0.45
    assert out[0, 0] == pytest.approx(expect, abs=1e-6)


def _depth_view(layout) -> dict[str, np.ndarray]:  # noqa: ANN001
    from react3d_core.camera import look_at

    run = layout.runs[0]
    T = run.frame.T
    eye = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1), -(run.depth + 1.6), 1.4]) + T[:3, 3]
    tgt = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1), -0.5 * run.depth, 0.6]) + T[:3, 3]
    K = scale_K(base_intrinsics(np.random.default_rng(0)), DEPTH_SIZE[0])
    return RayCaster(layout.mesh).cast(K, look_at(eye, tgt), *DEPTH_SIZE)


def test_dark_dropout_drops_dark_surfaces_only() -> None:
    """On a dark kitchen seen head-on: black and dark fronts lose most readings, light surfaces (walls,
    floor, light fronts, metal handles) keep nearly all of theirs (glossy ones lose a patch near the
    mirror direction)."""
    drop_dark, drop_light, n_dark, n_light = 0, 0, 0, 0
    for seed in range(3):
        layout = build_room(seed, "dark")
        hit = _depth_view(layout)
        albedo = linear_albedo(layout.face_colors)
        drop = dark_dropout(hit, albedo, layout.face_materials, np.random.default_rng(seed))
        face = hit["face"]
        a = np.where(face >= 0, albedo[np.maximum(face, 0)], -1.0)
        dark, light = (a >= 0) & (a < 0.02), a > 0.2
        drop_dark += int(drop[dark].sum())
        n_dark += int(dark.sum())
        drop_light += int(drop[light].sum())
        n_light += int(light.sum())
        assert not drop[face < 0].any()
    assert n_dark > 2000 and n_light > 2000
    assert drop_dark / n_dark > 0.9
    assert drop_light / n_light < 0.02


def test_synth_cli_new_kinds_and_dropout(tmp_path: Path) -> None:
    from flows.cli import main

    assert main(["synth", "--seed", "2", "--kind", "appliances", "--depth-dropout", "dark", "--frames", "1",
                 "--out", str(tmp_path / "s")]) == 0
    meta = json.loads((tmp_path / "s" / "synth_meta.json").read_text())
    assert meta["kind"] == "appliances" and meta["depth_dropout"] == "dark" and meta["pieces"]
    with pytest.raises(SystemExit):
        main(["synth", "--out", str(tmp_path / "t"), "--depth-dropout", "bright"])


@pytest.mark.slow
def test_dark_fronts_keep_little_tsdf_surface(synthetic_scene) -> None:  # noqa: ANN001
    """A dark-kind tuning room as the sets make it (60 frames, TSDF of the dropped depth): most dark
    fronts keep at most 30 % of their surface, light ones most of theirs; every front stays in the GT."""
    root = synthetic_scene(seed=340, n_frames=60, kind="dark", mesh="tsdf", depth_dropout="dark", misregister=(2, 1))
    layout = build_room(340, "dark")
    albedo = linear_albedo(layout.face_colors)
    meta = json.loads((root / "synth_meta.json").read_text())
    by_label = {p.label: p for p in layout.parts}
    dark, light = [], []
    for r in meta["parts"]:
        a = float(np.median(albedo[layout.face_keys == layout.key_ids[by_label[r["label"]].key]]))
        (dark if a < 0.05 else light if a > 0.2 else []).append(r["scan_coverage"])
    assert len(dark) >= 10 and np.quantile(dark, 0.75) <= 0.3
    assert not light or np.median(light) >= 0.8
    assert len(read_articulate3d(root / "articulate3d").movable) == len(layout.parts)
