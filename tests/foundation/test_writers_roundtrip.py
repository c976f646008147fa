"""Each layout written from a SceneInput loads back with the same poses, intrinsics, frame ids and depth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_depth
from react3d_core.scene_io.writers import WRITERS, write_scannetpp_iphone
from tests.foundation.test_load_scene import make_iphone


@pytest.mark.parametrize("layout", sorted(WRITERS))
def test_roundtrip(tmp_path: Path, layout: str) -> None:
    src = load_scene(make_iphone(tmp_path / "src"))
    back = load_scene(WRITERS[layout](src, tmp_path / layout))
    assert back.source_format == layout
    ids = [f.frame_id for f in src.frames]
    assert [f.frame_id for f in back.frames] == ids
    for a, b in zip(src.frames, back.frames):
        assert np.abs(a.c2w - b.c2w).max() <= 1e-6
        assert np.allclose(a.intrinsics.K, b.intrinsics.K, atol=1e-6) and a.intrinsics.width == b.intrinsics.width
        assert np.abs(read_depth(a.depth) - read_depth(b.depth)).max() <= 1e-3


def test_depth_bin_both_encodings(tmp_path: Path) -> None:
    src = load_scene(make_iphone(tmp_path / "src"))
    for enc, kind in (("per_frame", "depth_bin_lz4"), ("stream", "depth_bin_deflate_stream")):
        back = load_scene(write_scannetpp_iphone(src, tmp_path / enc, depth_encoding=enc))
        assert back.frames[0].depth.kind == kind
        assert read_depth(back.frames[3].depth) == pytest.approx(np.full((192, 256), 1.75, np.float32), abs=1e-3)
