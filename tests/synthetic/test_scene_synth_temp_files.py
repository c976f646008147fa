"""Building a scene-synthesizer kitchen leaves nothing in /tmp (the library writes its procedural door,
handle and sink meshes there and never removes them: ~60 files per kitchen)."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

PREFIXES = ("cabinet_door_", "cabinet_handle_", "refrigerator_", "freezer_", "sink_", "microwave_handle_")


def _new_asset_files(since: float) -> list[Path]:
    return [p for p in Path("/tmp").iterdir()
            if p.name.startswith(PREFIXES) and p.suffix == ".obj" and p.stat().st_mtime >= since]


def test_kitchen_assets_do_not_leak_into_tmp() -> None:
    pytest.importorskip("scene_synthesizer")
    import scene_synthesizer.utils as utils

    from react3d_core.synthetic.from_scene_synthesizer import build_scene_synthesizer

    real = utils.get_random_filename
    t0 = time.time() - 1
    layout = build_scene_synthesizer(seed=5)
    assert len(layout.parts) > 10  # a real kitchen was built from those meshes
    assert _new_asset_files(t0) == []
    assert utils.get_random_filename is real  # the library is left as it was
    assert os.access("/tmp", os.W_OK)
