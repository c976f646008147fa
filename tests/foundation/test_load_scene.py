"""load_scene on tiny hand-made scenes: ScanNet++ iPhone layout, validation errors, frame selection."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from react3d_core.camera import look_at, opencv_to_opengl_c2w
from react3d_core.config.scene_io import FrameSelectionConfig
from react3d_core.data.mesh import TriMesh, save_mesh
from react3d_core.errors import InputError
from react3d_core.scene_io import load_scene, select_frames
from react3d_core.scene_io.depth_bin import write_depth_bin
from react3d_core.scene_io.images import read_depth, read_rgb

K1920 = [[1500.0, 0, 960.0], [0, 1500.0, 720.0], [0, 0, 1]]


def _poses(n: int) -> list[np.ndarray]:
    return [look_at(np.array([0.5 * i, -2.0, 1.5]), np.array([0.0, 0.0, 0.5])) for i in range(n)]


def make_iphone(root: Path, n: int = 4, encoding: str = "per_frame", size=(96, 72)) -> Path:
    ip = root / "iphone"
    (ip / "rgb").mkdir(parents=True)
    (root / "scans").mkdir()
    save_mesh(root / "scans" / "mesh_aligned_0.05.ply", TriMesh(np.eye(3), np.array([[0, 1, 2]])))
    meta = {}
    for i, T in enumerate(_poses(n)):
        key = f"frame_{i:06d}"
        meta[key] = {"intrinsic": K1920, "aligned_pose": T.tolist(), "timestamp": float(i)}
        cv2.imwrite(str(ip / "rgb" / f"{key}.jpg"), np.full((size[1], size[0], 3), (40 * i) % 256, np.uint8))
    (ip / "pose_intrinsic_imu.json").write_text(json.dumps(meta))
    depths = np.stack([np.full((192, 256), 1.0 + 0.25 * i, np.float32) for i in range(n)])
    write_depth_bin(ip / "depth.bin", depths, encoding=encoding)
    (root / "articulate3d").mkdir()
    return root


@pytest.mark.parametrize("encoding", ["per_frame", "stream"])
def test_iphone_layout(tmp_path: Path, encoding: str) -> None:
    root = make_iphone(tmp_path / "scene", encoding=encoding)
    s = load_scene(root)
    assert s.source_format == "scannetpp_iphone" and len(s.frames) == 4
    assert s.gt_dir == root / "articulate3d"
    f = s.frames[2]
    # K for 1920x1440 rescaled to the 96x72 image: factor 0.05.
    assert (f.intrinsics.fx, f.intrinsics.cx, f.intrinsics.cy, f.intrinsics.width) == pytest.approx((75.0, 48.0, 36.0, 96))
    assert f.depth_intrinsics.fx == pytest.approx(1500 * 256 / 1920)
    assert np.abs(f.c2w - _poses(4)[2]).max() <= 1e-9
    assert read_rgb(f.rgb).shape == (72, 96, 3)
    assert read_depth(f.depth) == pytest.approx(np.full((192, 256), 1.5, np.float32), abs=1e-3)


def test_mismatched_depth_count(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "scene")
    write_depth_bin(root / "iphone" / "depth.bin", np.ones((3, 192, 256), np.float32))
    with pytest.raises(InputError, match="holds 3 depth frames"):
        load_scene(root)


@pytest.mark.parametrize("bad,msg", [
    (lambda T: np.full((4, 4), np.nan), "NaN"),
    (lambda T: np.diag([2.0, 1, 1, 1]), "orthonormal"),
    (lambda T: np.diag([-1.0, 1, 1, 1]), "reflection"),
])
def test_bad_pose(tmp_path: Path, bad, msg: str) -> None:
    root = make_iphone(tmp_path / "scene")
    p = root / "iphone" / "pose_intrinsic_imu.json"
    meta = json.loads(p.read_text())
    meta["frame_000001"]["aligned_pose"] = bad(None).tolist()
    p.write_text(json.dumps(meta))
    with pytest.raises(InputError, match=msg) as e:
        load_scene(root)
    assert "frame_000001" in str(e.value) and "\n" not in str(e.value)


def test_bad_intrinsics_and_missing_files(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "a")
    p = root / "iphone" / "pose_intrinsic_imu.json"
    meta = json.loads(p.read_text())
    meta["frame_000000"]["intrinsic"] = [[-5, 0, 1], [0, 5, 1], [0, 0, 1]]
    p.write_text(json.dumps(meta))
    with pytest.raises(InputError, match="positive"):
        load_scene(root)
    root = make_iphone(tmp_path / "b")
    (root / "iphone" / "rgb" / "frame_000003.jpg").unlink()
    with pytest.raises(InputError, match="image file not found"):
        load_scene(root)
    root = make_iphone(tmp_path / "c")
    (root / "scans" / "mesh_aligned_0.05.ply").write_bytes(b"")
    with pytest.raises(InputError, match="empty"):
        load_scene(root)
    with pytest.raises(InputError, match="no known scene layout"):
        load_scene(tmp_path)
    with pytest.raises(InputError, match="not found"):
        load_scene(tmp_path / "nope")


def test_generic_nerfstudio(tmp_path: Path) -> None:
    root = tmp_path / "g"
    root.mkdir()
    save_mesh(root / "mesh.ply", TriMesh(np.eye(3), np.array([[0, 1, 2]])))
    frames = []
    for i, T in enumerate(_poses(3)):
        cv2.imwrite(str(root / f"img{i}.png"), np.zeros((20, 30, 3), np.uint8))
        frames.append({"file_path": f"img{i}.png", "transform_matrix": opencv_to_opengl_c2w(T).tolist()})
    (root / "transforms.json").write_text(json.dumps({"fl_x": 20, "fl_y": 21, "cx": 15, "cy": 10, "w": 30, "h": 20, "frames": frames}))
    s = load_scene(root)
    assert s.source_format == "generic" and [f.frame_id for f in s.frames] == ["img0", "img1", "img2"]
    assert np.abs(s.frames[1].c2w - _poses(3)[1]).max() <= 1e-9


def test_selection_stride_cap_keyframes(tmp_path: Path) -> None:
    s = load_scene(make_iphone(tmp_path / "s", n=10))
    ids = lambda fs: [int(f.frame_id[-2:]) for f in fs]  # noqa: E731
    assert ids(select_frames(s.frames, FrameSelectionConfig(stride=3))) == [0, 3, 6, 9]
    # stride 1, cap 4 over 10 frames: round(linspace(0, 9, 4)) = 0, 3, 6, 9
    assert ids(select_frames(s.frames, FrameSelectionConfig(stride=1, max_frames=4))) == [0, 3, 6, 9]
    # cameras 0.5 m apart: translation threshold 1.2 m keeps every third frame (1.5 m), 0.4 m keeps all.
    kf = FrameSelectionConfig(stride=1, keyframes=True, keyframe_translation_m=1.2, keyframe_rotation_deg=179.0)
    assert ids(select_frames(s.frames, kf)) == [0, 3, 6, 9]
    kf = FrameSelectionConfig(stride=1, keyframes=True, keyframe_translation_m=0.4, keyframe_rotation_deg=179.0)
    assert len(select_frames(s.frames, kf)) == 10
    assert len(load_scene(s.root, FrameSelectionConfig(stride=2)).frames) == 5


def test_corrupt_and_empty_mesh(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "a")
    mesh = root / "scans" / "mesh_aligned_0.05.ply"
    mesh.write_bytes(b"garbage\x00\x01")
    with pytest.raises(InputError, match="not a PLY"):
        load_scene(root)
    save_mesh(mesh, TriMesh(np.zeros((0, 3)), np.zeros((0, 3), int)))
    with pytest.raises(InputError, match="empty mesh"):
        load_scene(root)


def test_generic_scannetpp_world_flag(tmp_path: Path) -> None:
    from react3d_core.camera import c2w_to_nerfstudio_scannetpp

    root = tmp_path / "dslr" / "nerfstudio"
    root.mkdir(parents=True)
    save_mesh(root / "mesh.ply", TriMesh(np.eye(3), np.array([[0, 1, 2]])))
    cv2.imwrite(str(root / "a.jpg"), np.zeros((20, 30, 3), np.uint8))
    T = _poses(2)[1]
    fr = [{"file_path": "a.jpg", "transform_matrix": c2w_to_nerfstudio_scannetpp(T).tolist()}]
    (root / "transforms.json").write_text(json.dumps({"fl_x": 20, "fl_y": 20, "cx": 15, "cy": 10, "w": 30, "h": 20, "frames": fr}))
    assert np.abs(load_scene(root).frames[0].c2w - T).max() <= 1e-9  # auto-detected from dslr/nerfstudio
    assert np.abs(load_scene(root, scannetpp_world=False).frames[0].c2w - T).max() > 0.1


def test_iphone_rgb_mkv_and_gt_part_ids(tmp_path: Path) -> None:
    import shutil

    root = make_iphone(tmp_path / "m")
    shutil.rmtree(root / "iphone" / "rgb")
    wr = cv2.VideoWriter(str(root / "iphone" / "rgb.mkv"), cv2.VideoWriter_fourcc(*"FFV1"), 10, (96, 72))
    for i in range(4):
        wr.write(np.full((72, 96, 3), 40 * i, np.uint8))
    wr.release()
    (root / "iphone" / "gt_part_ids").mkdir()
    cv2.imwrite(str(root / "iphone" / "gt_part_ids" / "frame_000001.png"), np.ones((72, 96), np.uint16))
    s = load_scene(root)
    f = s.frames[2]
    assert f.rgb.kind == "mkv" and f.rgb.index == 2 and f.intrinsics.width == 96
    assert read_rgb(f.rgb).mean() == pytest.approx(80.0, abs=1.0)
    assert s.frames[1].part_ids is not None and s.frames[0].part_ids is None
