"""load_scene and inspect on a scene from the shared synthetic writer (skipped until react3d_core.synthetic exists)."""

from __future__ import annotations

import importlib
import importlib.util
import json

import numpy as np
import pytest

from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_depth, read_rgb

_HAS_SYNTH = importlib.util.find_spec("react3d_core.synthetic") is not None and hasattr(
    importlib.import_module("react3d_core.synthetic"), "generate_scene")


@pytest.mark.skipif(not _HAS_SYNTH, reason="react3d_core.synthetic.generate_scene not written yet")
def test_synthetic_scene_loads(synthetic_scene) -> None:  # noqa: ANN001
    from flows.commands.inspect import summarize

    root = synthetic_scene(n_frames=12)
    meta = json.loads((root / "iphone" / "pose_intrinsic_imu.json").read_text())
    s = load_scene(root)
    assert s.source_format == "scannetpp_iphone" and len(s.frames) == len(meta) == 12
    assert s.gt_dir is not None and any(f.part_ids is not None for f in s.frames)
    f = s.frames[0]
    rgb = read_rgb(f.rgb)
    assert (rgb.shape[1], rgb.shape[0]) == (f.intrinsics.width, f.intrinsics.height)
    k = np.array(meta[f.frame_id]["intrinsic"]) * (f.intrinsics.width / 1920)
    assert f.intrinsics.fx == pytest.approx(k[0, 0])
    assert read_depth(f.depth).shape == (192, 256)
    assert summarize(str(root))[1] == []


@pytest.mark.skipif(not _HAS_SYNTH, reason="react3d_core.synthetic.generate_scene not written yet")
@pytest.mark.parametrize("layout", ["prepared", "generic"])
def test_synthetic_scene_roundtrips_through_every_layout(synthetic_scene, tmp_path, layout) -> None:  # noqa: ANN001
    from react3d_core.scene_io.writers import WRITERS

    src = load_scene(synthetic_scene(n_frames=12))
    back = load_scene(WRITERS[layout](src, tmp_path / layout))
    assert [f.frame_id for f in back.frames] == [f.frame_id for f in src.frames]
    for a, b in zip(src.frames, back.frames):
        assert np.abs(a.c2w - b.c2w).max() <= 1e-6
        assert np.allclose(a.intrinsics.K, b.intrinsics.K, atol=1e-6)
        assert np.abs(read_depth(a.depth) - read_depth(b.depth)).max() <= 1e-3
