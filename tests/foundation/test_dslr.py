"""ScanNet++ DSLR layout: COLMAP w2c poses, fisheye undistortion into a cache, depth rendered from the mesh."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from react3d_core.camera import c2w_to_colmap, look_at
from react3d_core.config.scene_io import FrameSelectionConfig
from react3d_core.data.mesh import TriMesh, save_mesh
from react3d_core.errors import InputError
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_depth, read_rgb


def make_dslr(root: Path, n: int = 3, w: int = 64, h: int = 48) -> tuple[Path, list[np.ndarray]]:
    (root / "scans").mkdir(parents=True)
    # a floor square 2x2 m at z = 0
    save_mesh(root / "scans" / "mesh_aligned_0.05.ply",
              TriMesh(np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.0]]), np.array([[0, 1, 2], [0, 2, 3]])))
    col = root / "dslr" / "colmap"
    col.mkdir(parents=True)
    (root / "dslr" / "resized_images").mkdir()
    (col / "cameras.txt").write_text(f"# cam\n1 OPENCV_FISHEYE {w} {h} 40 40 30 25 0.01 0.0 0.0 0.0\n")
    poses, lines = [], ["# images"]
    for i in range(n):
        T = look_at(np.array([0.1 * i, 0.0, 2.0]), np.array([0.1 * i, 0.01, 0.0]))
        q, t = c2w_to_colmap(T)
        poses.append(T)
        lines += [f"{i + 1} {' '.join(f'{x:.12f}' for x in (*q, *t))} 1 DSC{i:05d}.JPG", ""]
        cv2.imwrite(str(root / "dslr" / "resized_images" / f"DSC{i:05d}.JPG"), np.full((h, w, 3), 100, np.uint8))
    (col / "images.txt").write_text("\n".join(lines) + "\n")
    return root, poses


def test_dslr_load(tmp_path: Path) -> None:
    root, poses = make_dslr(tmp_path / "s")
    before = sorted(p for p in root.rglob("*"))
    cache = tmp_path / "cache"
    s = load_scene(root, FrameSelectionConfig(stride=2), cache_dir=cache)
    assert sorted(p for p in root.rglob("*")) == before  # inputs untouched
    assert s.source_format == "scannetpp_dslr" and [f.frame_id for f in s.frames] == ["DSC00000", "DSC00002"]
    f = s.frames[1]
    assert np.abs(f.c2w - poses[2]).max() <= 1e-6
    assert (f.intrinsics.cx, f.intrinsics.cy) == (32.0, 24.0)  # principal point forced to the centre
    assert read_rgb(f.rgb).shape == (48, 64, 3)
    d = read_depth(f.depth)
    # camera 2 m above the floor looking (almost) straight down: centre pixel depth ~2 m
    assert d[24, 32] == pytest.approx(2.0, abs=0.01)
    assert not (cache / "dslr" / "rgb" / "DSC00001.png").exists()  # unselected frames are not processed


def test_dslr_bad_camera(tmp_path: Path) -> None:
    root, _ = make_dslr(tmp_path / "s")
    (root / "dslr" / "colmap" / "cameras.txt").write_text("1 OPENCV_FISHEYE 64 48 -40 40 30 25 0 0 0 0\n")
    with pytest.raises(InputError, match="non-positive focal"):
        load_scene(root, cache_dir=tmp_path / "c")
