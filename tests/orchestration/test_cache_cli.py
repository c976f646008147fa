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


def test_cache_clean_prunes_the_quarantine(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    """Corrupt objects and store folders moved to the quarantine are pruned like everything else."""
    from flows.cli import main

    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("PREFECT_LOCAL_STORAGE_PATH", str(tmp_path / "storage"))
    q = tmp_path / "cache" / "quarantine"
    old_dir, new_obj = q / "export-ab12", q / "cd34.npz"
    (old_dir / "urdf").mkdir(parents=True)
    (old_dir / "urdf" / "scene.urdf").write_text("x")
    (q / "export-ab12.seal.json").write_text("{}")
    new_obj.write_text("x")
    past = time.time() - 10 * 86400
    for f in (old_dir, q / "export-ab12.seal.json"):
        os.utime(f, (past, past))
    assert main(["cache", "clean", "--older-than", "7"]) == 0
    assert not old_dir.exists() and not (q / "export-ab12.seal.json").exists() and new_obj.exists()
    assert main(["cache", "clean"]) == 0
    assert not new_obj.exists()


def test_cache_clean_prunes_collision_and_report_caches(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    """Convex decompositions and report pieces cached by content are pruned by age too."""
    from flows.cli import main

    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("PREFECT_LOCAL_STORAGE_PATH", str(tmp_path / "storage"))
    old_col = tmp_path / "cache" / "collisions" / "ab" / "convex-ab12.npz"
    new_rep = tmp_path / "cache" / "reports" / "cd" / "report-cd34.json"
    for f in (old_col, new_rep):
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("x")
    past = time.time() - 10 * 86400
    os.utime(old_col, (past, past))
    assert main(["cache", "clean", "--older-than", "7"]) == 0
    assert not old_col.exists() and new_rep.exists()
    assert main(["cache", "clean"]) == 0
    assert not new_rep.exists()
