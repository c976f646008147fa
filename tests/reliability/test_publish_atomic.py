"""A run killed at any point leaves the old output as it was, or the new one complete;
what killed runs left is cleaned by the next run, and only when it is ours."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from react3d_core.atomic import OUTPUT_MARKER, _HOST, atomic_dir, clean_leftovers

from .conftest import FAST, REPO, end_group, run_cli, snapshot

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def _marked(d: Path, files: dict[str, str]) -> Path:
    d.mkdir(parents=True)
    (d / OUTPUT_MARKER).write_text(json.dumps({"react3d": "0.1.0", "kind": "scene"}))
    for k, v in files.items():
        (d / k).write_text(v)
    return d


def test_failure_inside_atomic_dir_keeps_the_old_output(tmp_path: Path) -> None:
    out = _marked(tmp_path / "out", {"scene.json": "old"})
    with pytest.raises(RuntimeError), atomic_dir(out, marker={"kind": "scene"}) as tmp:
        (tmp / "scene.json").write_text("new, half written")
        raise RuntimeError("killed mid-way")
    assert (out / "scene.json").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    with atomic_dir(out, marker={"kind": "scene"}) as tmp:
        (tmp / "scene.json").write_text("new")
        assert (out / "scene.json").read_text() == "old"  # nothing of the new run is visible before the rename
    assert (out / "scene.json").read_text() == "new" and json.loads((out / OUTPUT_MARKER).read_text())["react3d"]


def test_only_our_leftovers_of_dead_processes_are_cleaned(tmp_path: Path) -> None:
    dead, alive = _dead_pid(), os.getppid()
    out = _marked(tmp_path / "out", {"scene.json": "current"})
    ours_old = _marked(tmp_path / f".out.old-{dead}", {"scene.json": "80 MB of an old output"})
    ours_tmp = _marked(tmp_path / f".out.tmp-{dead}@{_HOST}-ab12", {"scene.json": "half"})
    running = _marked(tmp_path / f".out.tmp-{alive}@{_HOST}-cd34", {"scene.json": "being written"})
    other_host = _marked(tmp_path / f".out.tmp-{dead}@00000000-ef56", {"scene.json": "another machine's"})
    users = tmp_path / f".out.old-{dead - 1 if dead > 1 else dead + 1}"
    users.mkdir()
    (users / "thesis.tex").write_text("a user's folder hidden by an older release")
    other_name = _marked(tmp_path / f".result.old-{dead}", {"scene.json": "another output's"})
    removed = clean_leftovers(out, marked=True)
    assert sorted(removed) == sorted([ours_old, ours_tmp])
    for kept in (out, running, other_host, users, other_name):
        assert kept.exists(), kept
    assert (users / "thesis.tex").read_text().startswith("a user's")


def test_kill_between_the_two_renames_restores_the_previous_output(tmp_path: Path) -> None:
    dead = _dead_pid()
    _marked(tmp_path / f".out.old-{dead}@{_HOST}-0a0b", {"scene.json": "previous"})  # out itself is gone
    with pytest.raises(RuntimeError), atomic_dir(tmp_path / "out", marker={"kind": "scene"}):
        raise RuntimeError("this run fails too")
    assert (tmp_path / "out" / "scene.json").read_text() == "previous"


def test_kill_9_during_publish_keeps_the_old_output_then_next_run_completes(converted: Path, scan: Path,
                                                                            cli_env: dict, tmp_path: Path) -> None:
    """kill -9 by PID once the new output is being staged (after publish used to happen, before the
    report): the old output stays byte-identical; the next run cleans the leftover and publishes a
    complete output (config, timings, report, metrics)."""
    out = tmp_path / "out"
    shutil.copytree(converted, out)
    old = snapshot(out)
    old_json = (out / "scene.json").read_bytes()
    cmd = [sys.executable, "-m", "flows.cli", "convert", str(scan), "--out", str(out), *FAST, "--no-refine"]
    p = subprocess.Popen(cmd, cwd=REPO, env=cli_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
    seen = None
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and p.poll() is None:
            staged = [q for q in tmp_path.iterdir() if q.name.startswith(".out.tmp-") and (q / "scene.json").exists()]
            if staged or (out / "scene.json").read_bytes() != old_json:
                seen = staged
                os.kill(p.pid, signal.SIGKILL)
                break
            time.sleep(0.02)
        p.wait(timeout=30)
    finally:
        end_group(p.pid)
    assert seen, "the run finished (or never staged) before it could be killed mid-publish"
    assert p.returncode == -signal.SIGKILL
    assert snapshot(out) == old  # the old output is intact, not a half-new scene.json with config {}
    r = run_cli(["convert", str(scan), "--out", str(out), *FAST, "--no-refine"], cli_env)
    assert r.returncode == 0, r.stderr[-3000:]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["out"]  # the killed run's staging folder is gone
    m = json.loads((out / "scene.json").read_text())
    assert m["config"]["articulation"]["refine"] is False and {"total", "report"} <= set(m["timings"])
    assert (out / "report.html").is_file() and (out / "metrics.json").is_file()
