"""``--out`` never deletes what react3d did not create (the CLI in this process for
the refusals, which happen before anything starts; a real CLI process for the allowed replacement)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from .conftest import FAST, first_line, run_cli, run_cli_here, snapshot

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


def _refused(r, command: str, path: Path, words: str) -> None:  # noqa: ANN001
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    line = first_line(r.stderr)
    assert line.startswith(f"react3d {command}: error: "), r.stderr[-2000:]
    assert str(path) in line and words in line, line
    assert "Traceback" not in r.stderr


def _world(tmp_path: Path, scan: Path) -> tuple[Path, Path]:
    """A user's home: a scan copy and a folder of their own documents."""
    s = tmp_path / "data" / "S"
    shutil.copytree(scan, s)
    docs = tmp_path / "mydocs"
    docs.mkdir()
    (docs / "thesis.tex").write_text("\\documentclass{article} years of work\n")
    (tmp_path / "notes.txt").write_text("a regular file\n")
    return s, docs


@pytest.mark.parametrize("target, words", [
    ("mydocs", "is not a react3d output"),     # a user's folder: thesis.tex was deleted before
    ("data/S", "is the input"),                # the scan itself
    ("data", "contains the input"),            # the scan's parent
    ("notes.txt", "is a file"),                # a regular file used to become a folder
    ("link", "symbolic link"),                 # a link to the user's folder
])
def test_convert_refuses_an_unsafe_out_and_touches_nothing(target: str, words: str, scan: Path, tmp_path: Path) -> None:
    s, docs = _world(tmp_path, scan)
    (tmp_path / "link").symlink_to(docs)
    before = snapshot(tmp_path)
    r = run_cli_here(["convert", str(s), "--out", str(tmp_path / target), *FAST])
    _refused(r, "convert", tmp_path / target, words)
    assert snapshot(tmp_path) == before  # nothing created, moved or hidden as .NAME.old-PID


def test_convert_dataset_refuses_parent_and_input_outputs(scan: Path, tmp_path: Path) -> None:
    s, docs = _world(tmp_path, scan)
    root = s.parent
    before = snapshot(tmp_path)
    # `--scenes ..` put one scene's output at the parent of --out (which then got replaced)
    r = run_cli_here(["convert-dataset", str(root), "--scenes", "..", "--out", str(docs / "results"), *FAST])
    _refused(r, "convert-dataset", root / "..", "scene id")
    # --out = the dataset's parent: data/S would be the output of scene ... no, `data` is: out/<scene> = input
    r = run_cli_here(["convert-dataset", str(root), "--out", str(root), *FAST])
    _refused(r, "convert-dataset", s, "is the input")
    # a user's folder where one scene's output would go
    (docs / "S").mkdir()
    (docs / "S" / "keep.txt").write_text("mine")
    before = snapshot(tmp_path)
    r = run_cli_here(["convert-dataset", str(root), "--out", str(docs), *FAST])
    _refused(r, "convert-dataset", docs / "S", "is not a react3d output")
    assert snapshot(tmp_path) == before


def test_synth_and_export_refuse_a_users_folder(tmp_path: Path) -> None:
    docs = tmp_path / "mydocs"
    (docs / "export" / "urdf").mkdir(parents=True)
    (docs / "thesis.tex").write_text("mine")
    (docs / "export" / "urdf" / "robot.urdf").write_text("<robot/>")
    (docs / "scene.json").write_text('{"objects": []}')
    before = snapshot(tmp_path)
    r = run_cli_here(["synth", "--out", str(docs), "--frames", "2"])
    _refused(r, "synth", docs, "is not a react3d output")
    r = run_cli_here(["export", str(docs), "--formats", "urdf"])
    _refused(r, "export", docs, "is not a react3d conversion output")
    assert snapshot(tmp_path) == before


def test_previous_output_is_replaced_whole_and_marked(converted: Path, scan: Path, cli_env: dict, tmp_path: Path) -> None:
    """The allowed case: a folder react3d wrote is replaced by a complete new output, nothing left beside it."""
    out = tmp_path / "out"
    shutil.copytree(converted, out)
    (out / "meshes" / "stale.ply").write_text("from an older run")  # must not survive the replacement
    r = run_cli(["convert", str(scan), "--out", str(out), *FAST, "--no-refine"], cli_env)
    assert r.returncode == 0, r.stderr[-3000:]
    import json

    marker = json.loads((out / ".react3d-output").read_text())
    assert marker["kind"] == "scene" and marker["react3d"]
    m = json.loads((out / "scene.json").read_text())
    assert m["config"]["articulation"]["refine"] is False and m["timings"]["report"] > 0
    assert (out / "report.html").stat().st_size > 10_000 and (out / "metrics.json").is_file()
    assert not (out / "meshes" / "stale.ply").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no .out.old-PID / .out.tmp-* left


def test_demo_refuses_a_users_folder_where_its_scene_goes(tmp_path: Path) -> None:
    (tmp_path / "demo_out" / "scene").mkdir(parents=True)
    (tmp_path / "demo_out" / "scene" / "notes.txt").write_text("mine")
    before = snapshot(tmp_path)
    r = run_cli_here(["demo", "--out", str(tmp_path / "demo_out")])
    _refused(r, "demo", tmp_path / "demo_out" / "scene", "is not a react3d output")
    assert snapshot(tmp_path) == before
