"""Benchmark work folders: a ``--work`` the user filled is refused untouched; one a benchmark made is cleared."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _workdir import MARKER, bench_workdir  # noqa: E402


def test_a_users_folder_is_refused_and_left_as_it_was(tmp_path: Path) -> None:
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "thesis.tex").write_text("keep")
    with pytest.raises(SystemExit, match="not made by a react3d benchmark"):
        bench_workdir(mine, fresh=True)
    assert sorted(p.name for p in mine.iterdir()) == ["thesis.tex"]
    with pytest.raises(SystemExit, match="is a file"):
        bench_workdir(mine / "thesis.tex")


def test_a_benchmark_folder_is_made_marked_and_cleared(tmp_path: Path) -> None:
    work = bench_workdir(tmp_path / "new" / "work")
    assert (work / MARKER).is_file()
    (work / "out").mkdir()
    (work / "out" / "scene.json").write_text("{}")
    (work / "log.txt").write_text("x")
    assert sorted(p.name for p in bench_workdir(work).iterdir()) == [MARKER, "log.txt", "out"]  # kept without fresh
    assert [p.name for p in bench_workdir(work, fresh=True).iterdir()] == [MARKER]
