"""`react3d cache clean --older-than D` prunes old records and store objects, keeps recent ones."""

from __future__ import annotations

import os
import time
from pathlib import Path


def test_cache_clean_older_than(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    from flows.cli import main

    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("PREFECT_LOCAL_STORAGE_PATH", str(tmp_path / "storage"))
    old_rec, new_rec = tmp_path / "storage" / "old", tmp_path / "storage" / "new"
    old_obj = tmp_path / "cache" / "objects" / "ab" / "ab12.npz"
    old_scene = tmp_path / "cache" / "scenes" / "cd" / "assembly-cd34"
    for f in (old_rec, new_rec, old_obj, old_scene / "scene.json"):
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("x")
    past = time.time() - 10 * 86400
    for f in (old_rec, old_obj, old_scene):
        os.utime(f, (past, past))
    assert main(["cache", "clean", "--older-than", "7"]) == 0
    assert not old_rec.exists() and not old_obj.exists() and not old_scene.exists()
    assert new_rec.exists()
    assert main(["cache", "clean"]) == 0
    assert not new_rec.exists()
