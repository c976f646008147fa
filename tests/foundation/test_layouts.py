"""The layout registry: every registered input layout is recognised and loaded from a tiny folder of its
own, each folder is recognised by its layout alone, an unknown folder gets one line naming what each
layout looks for, and detection and loading go through the registry and nowhere else."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

import react3d_core.scene_io as scene_io
from react3d_core.camera import K_SIZE, look_at, opencv_to_opengl_c2w
from react3d_core.config.scene_io import FrameSelectionConfig
from react3d_core.data.frames import Frame, ImageRef, Intrinsics, SceneInput
from react3d_core.data.mesh import TriMesh, save_mesh
from react3d_core.errors import InputError
from react3d_core.scene_io import layouts
from react3d_core.scene_io.layout import Layout, LoadOptions
from tests.foundation.test_dslr import make_dslr
from tests.foundation.test_load_scene import make_iphone

SCENE_IO = Path(scene_io.__file__).parent
TRIANGLE = TriMesh(np.eye(3), np.array([[0, 1, 2]]))


def _poses(n: int) -> list[np.ndarray]:
    return [look_at(np.array([0.4 * i, -2.0, 1.5]), np.array([0.0, 0.0, 0.5])) for i in range(n)]


def _iphone(root: Path) -> tuple[Path, list[np.ndarray]]:
    poses = [look_at(np.array([0.5 * i, -2.0, 1.5]), np.array([0.0, 0.0, 0.5])) for i in range(4)]  # make_iphone's
    return make_iphone(root, n=4), poses


def _prepared(root: Path) -> tuple[Path, list[np.ndarray]]:
    """Three frames in the json, images for two of them (the layout keeps only frames with an image)."""
    (root / "images_2").mkdir(parents=True)
    (root / "depth").mkdir()
    save_mesh(root / "mesh_aligned_0.05.ply", TRIANGLE)
    K = [[1500.0, 0, 960.0], [0, 1500.0, 720.0], [0, 0, 1]]
    poses = _poses(3)
    meta = {f"frame_{i:06d}": {"intrinsic": K, "aligned_pose": T.tolist()} for i, T in enumerate(poses)}
    (root / "pose_intrinsic_imu.json").write_text(json.dumps(meta))
    for i in (0, 2):
        cv2.imwrite(str(root / "images_2" / f"frame_{i:06d}.png"), np.zeros((72, 96, 3), np.uint8))
        cv2.imwrite(str(root / "depth" / f"frame_{i:06d}.png"), np.full((192, 256), 1500, np.uint16))
    return root, [poses[0], poses[2]]


def _generic(root: Path) -> tuple[Path, list[np.ndarray]]:
    root.mkdir(parents=True)
    save_mesh(root / "scan.ply", TRIANGLE)
    poses = _poses(2)
    frames = []
    for i, T in enumerate(poses):
        cv2.imwrite(str(root / f"im{i}.png"), np.zeros((20, 30, 3), np.uint8))
        frames.append({"file_path": f"im{i}.png", "transform_matrix": opencv_to_opengl_c2w(T).tolist()})
    meta = {"fl_x": 20, "fl_y": 20, "cx": 15, "cy": 10, "w": 30, "h": 20, "frames": frames}
    (root / "transforms.json").write_text(json.dumps(meta))
    return root, poses


def _dslr(root: Path) -> tuple[Path, list[np.ndarray]]:
    return make_dslr(root, n=2)


FIXTURES = {"scannetpp_iphone": _iphone, "prepared": _prepared, "generic": _generic, "scannetpp_dslr": _dslr}


def test_every_registered_layout_has_a_fixture_here() -> None:
    assert [lay.name for lay in layouts.LAYOUTS] == ["scannetpp_iphone", "prepared", "generic", "scannetpp_dslr"]
    assert set(FIXTURES) == {lay.name for lay in layouts.LAYOUTS}  # a new layout needs a fixture below


@pytest.mark.parametrize("name", sorted(FIXTURES))
def test_each_layout_round_trips_detect_then_load(tmp_path: Path, name: str) -> None:
    root, poses = FIXTURES[name](tmp_path / name)
    assert [lay.name for lay in layouts.LAYOUTS if lay.detect(root)] == [name]  # recognised by its layout only
    assert scene_io.detect_layout(root) == name
    s = scene_io.load_scene(root, cache_dir=tmp_path / "cache")
    assert s.source_format == name and s.root == root and s.mesh_path.is_file()
    assert len(s.frames) == len(poses)
    for f, T in zip(s.frames, poses):
        assert np.abs(f.c2w - T).max() <= 1e-6  # every layout hands out camera-to-world, OpenCV axes
    assert scene_io.load_scene(root, layout=name, cache_dir=tmp_path / "cache").frames == s.frames


def test_unknown_folder_names_what_each_layout_looks_for(tmp_path: Path) -> None:
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "a.jpg").write_bytes(b"")
    with pytest.raises(InputError, match="no known scene layout") as e:
        scene_io.load_scene(tmp_path / "photos")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(str(tmp_path / "photos"))
    for lay in layouts.LAYOUTS:
        assert f"{lay.name}: {lay.looks_for}" in msg
    assert "dslr/colmap/images.txt" in msg and "transforms.json" in msg
    with pytest.raises(InputError, match="unsupported layout 'colmap'"):
        scene_io.load_scene(tmp_path / "photos", layout="colmap")


def _toy_layout(seen: list[str]) -> Layout:
    """A layout the registry did not ship with: a folder holding ``toy.txt``, one frame per line."""

    def detect(root: Path) -> bool:
        return (root / "toy.txt").is_file()

    def load(root: Path, options: LoadOptions) -> SceneInput:
        seen.append(root.name)
        K = Intrinsics(fx=10.0, fy=10.0, cx=5.0, cy=5.0, width=10, height=10)
        frames = tuple(Frame(frame_id=line, rgb=ImageRef(path=root / f"{line}.png", kind="png"), intrinsics=K,
                             pose=np.eye(4)) for line in (root / "toy.txt").read_text().split())
        return SceneInput(scene_id=root.name, root=root, mesh_path=root / "m.ply", frames=frames, source_format="toy")

    return Layout("toy", "toy.txt", detect, load)


def test_detection_and_loading_go_through_the_registry(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[str] = []
    monkeypatch.setattr(layouts, "LAYOUTS", (*layouts.LAYOUTS, _toy_layout(seen)))
    root = tmp_path / "t"
    root.mkdir()
    (root / "toy.txt").write_text("a b c d e")
    assert scene_io.detect_layout(root) == "toy"
    s = scene_io.load_scene(root, FrameSelectionConfig(stride=2))
    assert seen == ["t"] and s.source_format == "toy"
    assert [f.frame_id for f in s.frames] == ["a", "c", "e"] and "kept 3 of 5" in s.frame_selection  # selected after loading
    with pytest.raises(InputError, match="toy: toy.txt"):
        scene_io.detect_layout(tmp_path)


def test_a_layout_that_selects_while_loading_is_not_selected_twice(tmp_path: Path) -> None:
    root, _ = make_dslr(tmp_path / "d", n=5)
    s = scene_io.load_scene(root, FrameSelectionConfig(stride=2), cache_dir=tmp_path / "c")
    assert [f.frame_id for f in s.frames] == ["DSC00000", "DSC00002", "DSC00004"] and "kept 3 of 5" in s.frame_selection


def test_layout_names_are_written_only_in_their_own_module() -> None:
    """No module of scene_io branches on a layout's name: each name is a string in its own module only
    (other modules refer to ``module.NAME`` or go through the registry)."""
    names = {lay.name: Path(layouts.__file__).parent / f"{_module_of(lay)}.py" for lay in layouts.LAYOUTS}
    for path in sorted(SCENE_IO.glob("*.py")):
        strings = {n.value for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.Constant)}
        for name, home in names.items():
            assert name not in strings or path == home, f"{path.name} names the layout {name!r}"


def _module_of(layout: Layout) -> str:
    return layout.load.__module__.rsplit(".", 1)[-1]


def test_prepared_K_is_rescaled_from_the_sensor_size(tmp_path: Path) -> None:
    root, _ = _prepared(tmp_path / "p")
    f = scene_io.load_scene(root).frames[0]
    assert (f.intrinsics.width, f.intrinsics.height) == (96, 72)
    assert f.intrinsics.fx == pytest.approx(1500.0 * 96 / K_SIZE[0])  # 75.0
    assert f.depth_intrinsics.fx == pytest.approx(1500.0 * 256 / K_SIZE[0])  # 200.0
