"""Realistic synthetic scans: laser / TSDF meshes in the scene's frame with GT transferred, photo-like images."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from react3d_core.data.mesh import load_mesh
from react3d_core.ground_truth import read_articulate3d
from react3d_core.metrics import gt_to_scene, run_evaluation
from react3d_core.synthetic import generate_scene
from react3d_core.synthetic.materials import PhotoSettings, render_photo, scene_lights
from react3d_core.synthetic.procedural import build_room
from react3d_core.synthetic.remesh import canonical_mesh
from react3d_core.synthetic.render import RGB_SIZE, RayCaster, base_intrinsics, scale_K

SCENE = {"seed": 1, "n_frames": 5, "kind": "dresser"}


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _distances(points: np.ndarray, verts: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Distance of each point to the triangle mesh (verts, faces)."""
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(verts.astype(np.float32)), o3d.core.Tensor(faces.astype(np.uint32)))
    return scene.compute_distance(o3d.core.Tensor(points.astype(np.float32))).numpy()


@pytest.mark.parametrize("mesh", ["laser", "tsdf"])
def test_scan_mesh_is_in_the_clean_frame(synthetic_scene, mesh: str) -> None:  # noqa: ANN001
    root = synthetic_scene(mesh=mesh, **SCENE)
    scan = load_mesh(root / "scans" / "mesh_aligned_0.05.ply")
    clean = build_room(SCENE["seed"], SCENE["kind"]).mesh
    meta = json.loads((root / "synth_meta.json").read_text())
    assert meta["mesh"]["kind"] == mesh and meta["faces"] == scan.n_faces != clean.n_faces
    assert scan.n_faces > 5 * clean.n_faces  # a dense scan, not the 3 cm generator mesh
    d_scan = _distances(scan.vertices, clean.vertices, clean.faces)
    assert np.median(d_scan) < (0.002 if mesh == "laser" else 0.006)
    assert np.quantile(d_scan, 0.99) < 0.02
    # the other way round on what the capture sees: the fronts' surfaces are in the scan (median: the
    # slabs' back faces, 2 cm behind, are never observed)
    gt_clean = build_room(SCENE["seed"], SCENE["kind"])
    front = np.unique(clean.faces[np.isin(gt_clean.face_keys, [gt_clean.key_ids[p.key] for p in gt_clean.parts])].ravel())
    d_clean = _distances(clean.vertices[front], scan.vertices, scan.faces)
    assert np.median(d_clean) < 0.01
    assert scan.colors.std(0).max() > 5  # coloured, not a constant default


@pytest.mark.parametrize("mesh", ["laser", "tsdf"])
def test_transferred_gt_scores_perfect_and_lies_on_its_part(synthetic_scene, tmp_path: Path, mesh: str) -> None:  # noqa: ANN001
    root = synthetic_scene(mesh=mesh, **SCENE)
    gt = read_articulate3d(root / "articulate3d")
    scan = load_mesh(root / "scans" / "mesh_aligned_0.05.ply")
    meta = json.loads((root / "synth_meta.json").read_text())
    layout = build_room(SCENE["seed"], SCENE["kind"])
    assert gt.total_vertices == scan.n_vertices and len(gt.movable) == len(layout.parts) - len(meta["mesh"]["dropped_parts"])
    assert len(gt.movable) >= 3
    by_label = {p.label: p for p in layout.parts}
    for part in gt.movable:
        spec = by_label[part.label]
        faces = layout.mesh.faces[layout.face_keys == layout.key_ids[spec.key]]
        d = _distances(scan.vertices[part.vert_indices], layout.mesh.vertices, faces)
        assert d.max() <= 0.0101, part.label  # labelled only from its own surface, within 1 cm
        assert np.isin(scan.faces[part.tri_indices], part.vert_indices).sum(1).min() >= 2  # face majority
    gt_to_scene(gt, root / "scans" / "mesh_aligned_0.05.ply", tmp_path / "pred")
    res = run_evaluation(tmp_path / "pred", root / "articulate3d")
    for tau in ("0.25", "0.5"):
        a = res["aggregate"][tau]
        assert (a["f1"], a["precision"], a["recall"], a["joint_acc"]) == (1.0, 1.0, 1.0, 1.0)


@pytest.mark.parametrize("mesh", [pytest.param("laser", marks=pytest.mark.slow), "tsdf"])  # laser: ~21 s
def test_photo_and_scan_meshes_are_deterministic(synthetic_scene, tmp_path: Path, mesh: str) -> None:  # noqa: ANN001
    a = synthetic_scene(mesh=mesh, **SCENE)
    b = generate_scene(tmp_path / "b", mesh=mesh, **SCENE)
    files = ["scans/mesh_aligned_0.05.ply", "iphone/depth.bin"] + [f"iphone/rgb/frame_{i:06d}.jpg" for i in range(5)]
    assert all(_sha(a / f) == _sha(b / f) for f in files)
    gt_a = read_articulate3d(a / "articulate3d")
    gt_b = read_articulate3d(b / "articulate3d")
    assert [p.vert_indices.tolist() for p in gt_a.parts] == [p.vert_indices.tolist() for p in gt_b.parts]


def test_plain_and_photo_differ_only_in_colour(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    photo = synthetic_scene(**SCENE)
    plain = generate_scene(tmp_path / "plain", realism="plain", **SCENE)
    same = ["scans/mesh_aligned_0.05.ply", "iphone/depth.bin", "iphone/pose_intrinsic_imu.json",
            "iphone/gt_part_ids/frame_000002.png"]
    assert all(_sha(photo / f) == _sha(plain / f) for f in same)
    assert _sha(photo / "iphone/rgb/frame_000002.jpg") != _sha(plain / "iphone/rgb/frame_000002.jpg")
    assert json.loads((photo / "synth_meta.json").read_text())["realism"] == "photo"


def _seam_ratios(root: Path) -> list[float]:
    """Per frame and direction: median luminance on seams between two neighbouring fronts (GT ids 2 px
    left and right, or above and below, are two different movable parts) over the fronts either side."""
    meta = json.loads((root / "synth_meta.json").read_text())
    movable = np.array([r["part_id"] + 1 for r in meta["parts"]])
    ratios = []
    for i in range(meta["n_frames"]):
        ids = cv2.imread(str(root / "iphone" / "gt_part_ids" / f"frame_{i:06d}.png"), cv2.IMREAD_UNCHANGED).astype(np.int64)
        lum = cv2.imread(str(root / "iphone" / "rgb" / f"frame_{i:06d}.jpg")).astype(np.float32).mean(-1)
        for axis in (0, 1):
            a, b = np.roll(ids, 2, axis), np.roll(ids, -2, axis)
            seam = np.isin(a, movable) & np.isin(b, movable) & (a != b)
            seam[:4], seam[-4:], seam[:, :4], seam[:, -4:] = False, False, False, False
            if seam.sum() < 50:
                continue
            dark = np.minimum(np.minimum(np.roll(lum, 1, axis), lum), np.roll(lum, -1, axis))[seam]
            sides = 0.5 * (np.roll(lum, 4, axis) + np.roll(lum, -4, axis))[seam]
            ratios.append(float(np.median(dark / np.maximum(sides, 1.0))))
    return ratios


def test_front_seams_render_dark(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    """The 4 mm gaps between fronts show as thin dark lines in photo renders, as in real photos (the
    plain renderer lit the carcass edge behind the gap like the fronts)."""
    photo = _seam_ratios(synthetic_scene(**SCENE))
    plain = _seam_ratios(generate_scene(tmp_path / "plain", realism="plain", **SCENE))
    assert len(photo) >= 4 and min(photo) < 0.5 and np.median(photo) < 0.75
    assert np.median(photo) < np.median(plain) - 0.15


def _one_hit() -> tuple[dict[str, np.ndarray], object]:
    layout = build_room(3, "kitchen")
    rng = np.random.default_rng(0)
    K = scale_K(base_intrinsics(rng), RGB_SIZE[0])
    run = layout.runs[0]
    T = run.frame.T
    from react3d_core.camera import look_at

    eye = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1), -(run.depth + 1.5), 1.4]) + T[:3, 3]
    tgt = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1), 0.0, 0.6]) + T[:3, 3]
    return RayCaster(layout.mesh).cast(K, look_at(eye, tgt), *RGB_SIZE), layout


def test_misregistration_shifts_colour_by_the_asked_pixels() -> None:
    hit, layout = _one_hit()

    def render(shift: tuple[float, float], frame_seed: int = 1) -> np.ndarray:
        s = PhotoSettings(scene_lights(layout.room), misregister=shift, blur_px=0.0)
        return render_photo(hit, layout.mesh.faces, layout.mesh.colors, layout.face_materials, s,
                            np.random.default_rng(frame_seed), np.random.default_rng(2), layout.face_colors).astype(np.float32)

    base, moved = render((0.0, 0.0)), render((3.0, 2.0))
    # sensor noise is added after the shift at fixed pixels: smooth it away before comparing
    base, moved = cv2.GaussianBlur(base, (7, 7), 0), cv2.GaussianBlur(moved, (7, 7), 0)
    inner = (slice(20, -20), slice(20, -20))
    aligned = np.abs(moved[22:-18, 23:-17] - base[inner]).mean()
    unaligned = np.abs(moved[inner] - base[inner]).mean()
    assert aligned < 1.5 and 2 * aligned < unaligned
    # same seed, same image; another frame seed changes exposure, blur and white balance
    assert np.array_equal(cv2.GaussianBlur(render((3.0, 2.0)), (7, 7), 0), moved)
    assert np.abs(render((0.0, 0.0), frame_seed=5) - base).mean() > 1.0


def test_highlights_move_between_views() -> None:
    """Glossy and metal surfaces reflect the lights: the same surface point changes brightness with
    the viewpoint more than matte paint does (view-dependent shading)."""
    from react3d_core.synthetic.materials import GLOSSY, MATTE, METAL

    layout = build_room(2, "kitchen")  # glossy fronts, metal handles, matte walls
    mats = layout.face_materials
    caster = RayCaster(layout.mesh)
    rng = np.random.default_rng(0)
    K = scale_K(base_intrinsics(rng), 480)
    from react3d_core.camera import look_at

    run = layout.runs[0]
    T = run.frame.T
    tgt = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1), 0.0, 0.6]) + T[:3, 3]
    s = PhotoSettings(scene_lights(layout.room), blur_px=0.0, exposure_sigma=0.0)
    per_face = []
    for dx in (-0.8, 0.8):
        eye = T[:3, :3] @ np.array([0.5 * (run.x0 + run.x1) + dx, -(run.depth + 1.3), 1.5]) + T[:3, 3]
        hit = caster.cast(K, look_at(eye, tgt), 480, 360)
        img = render_photo(hit, layout.mesh.faces, layout.mesh.colors, mats, s, np.random.default_rng(0),
                           np.random.default_rng(0), layout.face_colors).astype(np.float32).mean(-1)
        f = hit["face"]
        acc = np.bincount(f[f >= 0], img[f >= 0], minlength=layout.mesh.n_faces)
        cnt = np.bincount(f[f >= 0], minlength=layout.mesh.n_faces)
        per_face.append((acc, cnt))
    both = (per_face[0][1] > 20) & (per_face[1][1] > 20)
    change = np.abs(per_face[0][0] / np.maximum(per_face[0][1], 1) - per_face[1][0] / np.maximum(per_face[1][1], 1))
    shiny = both & np.isin(mats, [GLOSSY, METAL])
    matte = both & (mats == MATTE)
    assert shiny.sum() > 10 and matte.sum() > 10
    assert np.median(change[shiny]) > 1.5 * np.median(change[matte])


def test_canonical_mesh_ignores_input_order() -> None:
    rng = np.random.default_rng(0)
    v = rng.random((30, 3))
    f = rng.integers(0, 30, (40, 3))
    a = canonical_mesh(v, f)
    perm = rng.permutation(30)
    inv = np.argsort(perm)
    b = canonical_mesh(v[perm], inv[f][rng.permutation(40)][:, [1, 2, 0]])
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def test_bench_sets_pass_scan_options() -> None:
    from flows.bench.runner import load_spec

    heldout = load_spec("heldout", Path("/nonexistent"))
    assert heldout[0]["name"] == "procedural_kitchen_100" and heldout[0]["synth"] == {}
    for mesh in ("laser", "tsdf"):
        entries = load_spec(f"heldout_{mesh}", Path("/nonexistent"))
        assert len(entries) == 11 and {e["seed"] for e in entries} == set(range(200, 211))
        assert all(e["synth"]["mesh"] == mesh and e["name"].endswith(f"_{mesh}_photo") for e in entries)
        assert [e.get("kind") for e in entries] == [e.get("kind") for e in heldout]
    tuning = load_spec("tuning_realistic", Path("/nonexistent"))
    assert {(e["seed"], e["synth"]["mesh"]) for e in tuning} == {(s, m) for s in range(10) for m in ("laser", "tsdf")}
    second = load_spec("tuning_realistic_2", Path("/nonexistent"))
    assert {(e["seed"], e["synth"]["mesh"]) for e in second} == {(s, m) for s in range(12, 18) for m in ("laser", "tsdf")}
    held = {e["seed"] for e in heldout} | set(range(200, 211))
    assert not held & ({e["seed"] for e in tuning} | {e["seed"] for e in second})  # tuning never touches held-apart seeds


HELD_APART = ("heldout", "heldout_laser", "heldout_tsdf", "large_kitchens", "free_standing_heldout", "glass_heldout", "dark_heldout")
TUNING = ("tuning_realistic", "tuning_realistic_2", "wardrobes_tuning", "large_kitchens_tuning", "free_standing_tuning",
          "free_standing_tuning_2", "glass_tuning", "glass_tuning_2", "dark_tuning", "dark_tuning_2")


def test_tuning_and_held_apart_seeds_never_overlap() -> None:
    """No seed of any tuning set is a seed of any held-apart set (whatever the kind), and every set file
    is one or the other (or the smoke check)."""
    from flows.bench.runner import SETS_DIR, load_spec

    seeds = {name: {e["seed"] for e in load_spec(name, Path("/nonexistent"))} for name in HELD_APART + TUNING}
    held = set().union(*(seeds[n] for n in HELD_APART))
    for name in TUNING:
        assert not seeds[name] & held, (name, sorted(seeds[name] & held))
    assert {p.stem for p in SETS_DIR.glob("*.json")} == set(HELD_APART + TUNING) | {"smoke"}


def test_new_held_apart_sets() -> None:
    """Free-standing (>= 8 scenes, >= 40 parts), glass and dark-front held-apart sets: realistic meshes,
    photo images, their own kinds; the dark one drops depth."""
    from flows.bench.runner import load_spec

    fs = load_spec("free_standing_heldout", Path("/nonexistent"))
    assert len(fs) >= 8 and {e["kind"] for e in fs} == {"furniture", "appliances"}
    assert sum(len(build_room(e["seed"], e["kind"]).parts) for e in fs) >= 40
    for name, kind in (("free_standing_heldout", None), ("glass_heldout", "glass"), ("dark_heldout", "dark")):
        entries = load_spec(name, Path("/nonexistent"))
        assert len(entries) >= 8 and all(e["synth"]["mesh"] in ("laser", "tsdf") and e["synth"]["realism"] == "photo" for e in entries)
        assert kind is None or {e["kind"] for e in entries} == {kind}
    dark = load_spec("dark_heldout", Path("/nonexistent"))
    assert all(e["synth"]["depth_dropout"] == "dark" and e["name"].endswith("_dropout-dark") for e in dark)


def test_synth_cli_scan_options(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    from flows.cli import main

    assert main(["synth", "--out", str(tmp_path / "s"), "--realism", "plain", "--misregister", "2,1", "--frames", "2"]) == 2
    assert "needs --realism photo" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["synth", "--out", str(tmp_path / "s"), "--misregister", "3"])
    assert main(["synth", "--seed", "1", "--kind", "dresser", "--out", str(tmp_path / "t"), "--frames", "2",
                 "--mesh", "tsdf", "--misregister", "2,1"]) == 0
    meta = json.loads((tmp_path / "t" / "synth_meta.json").read_text())
    assert meta["mesh"]["kind"] == "tsdf" and meta["realism"] == "photo" and meta["misregister_px"] == [2.0, 1.0]

