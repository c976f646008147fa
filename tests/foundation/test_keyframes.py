"""Keyframe selection by what the views add, on hand-made pose sequences.

Rules under test (FrameSelectionConfig defaults): keep a frame when the camera moved >= 5 cm or turned
>= 3 deg since the last kept one and, with a rasterizer, when >= 5 % of what it sees has been seen by
fewer than 10 kept frames; then an even cap of 300. An explicit stride is honoured as given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.camera import look_at
from react3d_core.config.scene_io import FrameSelectionConfig
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.raster import Rasterizer
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.selection import choose_frames
from react3d_core.synthetic.builder import MeshBuilder
from tests.foundation.test_load_scene import make_iphone

# 640 x 480, fx 500: 65 deg wide; at 2 m a view spans 2.56 m of wall
INTR = Intrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)


def _frames(poses: list[np.ndarray]) -> list[Frame]:
    return [Frame(frame_id=f"f{i:04d}", rgb=ImageRef(path=Path(f"f{i}.jpg"), kind="jpg"), intrinsics=INTR, pose=T)
            for i, T in enumerate(poses)]


def _walk(xs: np.ndarray) -> list[np.ndarray]:
    """Cameras at (x, 0, 1.5) looking along +y at a wall 2 m away."""
    return [look_at(np.array([x, 0.0, 1.5]), np.array([x, 2.0, 1.5])) for x in xs]


def _wall() -> Rasterizer:
    m = MeshBuilder(edge=0.25)
    m.add_box([-3.0, 2.0, 0.0], [6.0, 2.05, 3.0], (200, 200, 200))
    mesh, _, _ = m.build()
    return Rasterizer(mesh)


def _x(frames: list[Frame]) -> np.ndarray:
    return np.array([f.c2w[0, 3] for f in frames])


@pytest.mark.parametrize("with_mesh", [False, True])
def test_static_camera_keeps_one_frame(with_mesh: bool) -> None:
    sel = choose_frames(_frames(_walk(np.zeros(50))), FrameSelectionConfig(), _wall() if with_mesh else None)
    assert len(sel.frames) == 1 and sel.skipped_motion == 49
    assert sel.reason.startswith("kept 1 of 50 frames: keyframes by motion (>= 0.05 m or >= 3 deg)")


def test_pure_rotation_sweep_keeps_every_third_step() -> None:
    """Turning in place by 1.1 deg a frame: 2.2 deg < 3 is skipped, 3.3 deg is kept -> frames 0, 3, 6, ..."""
    poses = []
    for k in range(90):
        a = np.radians(1.1 * k)
        poses.append(look_at(np.zeros(3), np.array([np.cos(a), np.sin(a), 0.0])))
    sel = choose_frames(_frames(poses), FrameSelectionConfig())
    assert [f.frame_id for f in sel.frames] == [f"f{i:04d}" for i in range(0, 90, 3)]
    assert "60 too little motion" in sel.reason and "no coverage check" in sel.reason


def test_dense_and_sparse_walks_of_the_same_path_select_alike() -> None:
    """A 3.3 m walk filmed at 1.1 cm per frame (301 frames, 60 fps-like) and at 11 cm (31 frames): the
    sparse capture keeps every frame, the dense one a frame every 5.5 cm (5 steps); both cover the same
    path and every sparse pose has a dense keyframe within 3 cm."""
    rast = _wall()
    sparse = choose_frames(_frames(_walk(0.11 * np.arange(31))), FrameSelectionConfig(), rast)
    dense = choose_frames(_frames(_walk(0.011 * np.arange(301))), FrameSelectionConfig(), rast)
    assert len(sparse.frames) == 31
    xd = _x(dense.frames)
    assert len(xd) == 61 and np.allclose(np.diff(xd), 0.055)
    assert np.abs(_x(sparse.frames)[:, None] - xd[None]).min(1).max() <= 0.03
    assert dense.reason.startswith("kept 61 of 301 frames") and "240 too little motion" in dense.reason


def test_coverage_skips_a_second_pass_over_the_same_wall() -> None:
    """Walk 0 -> 3 m and back along a wall. The first pass adds surface at every step; on the way back
    the middle of the wall has been seen by 10+ kept frames, so frames there add nothing; near the ends
    (seen by few frames) they still do. Without a mesh (motion only) every frame is kept."""
    xs = np.concatenate([0.1 * np.arange(31), 0.1 * np.arange(29, -1, -1)])
    frames = _frames(_walk(xs))
    sel = choose_frames(frames, FrameSelectionConfig(), _wall())
    kept = {f.frame_id for f in sel.frames}
    assert all(f.frame_id in kept for f in frames[:31])  # first pass
    back = [f for f in frames[31:] if f.frame_id in kept]
    assert back and not any(1.0 <= x <= 2.0 for x in _x(back))
    assert sel.skipped_coverage == 30 - len(back) > 0 and "no new surface" in sel.reason
    assert len(choose_frames(frames, FrameSelectionConfig()).frames) == 61


def test_cap_and_explicit_stride() -> None:
    frames = _frames(_walk(0.1 * np.arange(40)))
    sel = choose_frames(frames, FrameSelectionConfig(keyframe_cap=5))
    # 40 keyframes, cap 5: round(linspace(0, 39, 5)) = 0, 10, 20, 29, 39
    assert [f.frame_id for f in sel.frames] == ["f0000", "f0010", "f0020", "f0029", "f0039"]
    assert sel.dropped_by_cap == 35 and sel.reason.startswith("kept 5 of 40 frames") and "35 by the cap" in sel.reason
    assert len(choose_frames(frames, FrameSelectionConfig(max_frames=4)).frames) == 4  # the explicit cap is tighter
    st = choose_frames(frames, FrameSelectionConfig(stride=5))
    assert [f.frame_id for f in st.frames] == [f"f{i:04d}" for i in range(0, 40, 5)]
    assert st.reason == "kept 8 of 40 frames: stride 5"


def test_load_scene_reports_the_selection(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "s", n=6)  # cameras 0.5 m apart: all move enough
    s = load_scene(root, FrameSelectionConfig(coverage_width=0))
    assert len(s.frames) == 6 and s.frame_selection.startswith("kept 6 of 6 frames: keyframes by motion")
    # by default load_scene builds a rasterizer of the scan (one triangle near the origin); the last
    # camera (2.5 m to the side) sees none of it and adds no surface
    s = load_scene(root, FrameSelectionConfig())
    assert "/coverage" in s.frame_selection and s.frame_selection.endswith("skipped 1 no new surface")
    assert load_scene(root, FrameSelectionConfig(stride=2)).frame_selection == "kept 3 of 6 frames: stride 2"
    assert load_scene(root).frame_selection == ""  # no selection asked for


def test_a_remembered_selection_is_reused_and_follows_poses_and_mesh(tmp_path: Path) -> None:
    from react3d_core.data.mesh import save_mesh
    from react3d_core.scene_io.selection import choose_frames_memo, selection_key

    class Memo(dict):
        def get(self, key):  # noqa: ANN001, ANN201
            return super().get(key)

        def put(self, key, value) -> None:  # noqa: ANN001
            self[key] = value

    wall = _wall()
    mesh = tmp_path / "wall.ply"
    save_mesh(mesh, wall.mesh)
    frames = _frames(_walk(np.r_[np.linspace(0, 3, 31), np.linspace(3, 0, 31)]))  # the wall walked twice
    cfg = FrameSelectionConfig()
    memo, built = Memo(), []

    def raster() -> Rasterizer:
        built.append(1)
        return wall

    first = choose_frames_memo(frames, cfg, mesh, raster, memo)
    assert built == [1] and len(memo) == 1
    assert [f.frame_id for f in first.frames] == [f.frame_id for f in choose_frames(frames, cfg, wall).frames]

    def no_raster() -> Rasterizer:
        raise AssertionError("a remembered selection renders nothing")

    again = choose_frames_memo(frames, cfg, mesh, no_raster, memo)
    assert [f.frame_id for f in again.frames] == [f.frame_id for f in first.frames] and again.reason == first.reason

    key = selection_key(frames, cfg, mesh)
    moved = _frames(_walk(np.r_[np.linspace(0, 3, 31), np.linspace(3, 0.1, 31)]))
    assert selection_key(moved, cfg, mesh) != key  # another pose
    assert selection_key(frames, cfg.model_copy(update={"coverage_min_new": 0.2}), mesh) != key  # another setting
    mesh.write_bytes(mesh.read_bytes() + b"\n")
    assert selection_key(frames, cfg, mesh) != key  # another mesh file
    assert choose_frames_memo(frames, cfg.model_copy(update={"stride": 2}), mesh, no_raster, memo).total == 62
