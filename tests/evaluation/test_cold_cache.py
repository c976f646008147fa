"""``bench --cold`` runs each scene in a cache folder it made itself and removes only that folder."""

from __future__ import annotations

import os
from pathlib import Path

from flows.bench.runner import cold_cache


def test_cold_cache_is_fresh_and_removes_only_itself(tmp_path: Path) -> None:
    mine = tmp_path / "cold-cache"  # a user's folder with the name an earlier version used
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    before = os.environ.get("REACT3D_CACHE")
    with cold_cache(tmp_path) as root:
        assert root.parent == tmp_path and root != mine and not any(root.iterdir())
        assert os.environ["REACT3D_CACHE"] == str(root / "react3d")
        (root / "react3d").mkdir()
        (root / "react3d" / "obj").write_bytes(b"x")
    assert not root.exists()
    assert (mine / "notes.txt").read_text() == "keep"
    assert os.environ.get("REACT3D_CACHE") == before
