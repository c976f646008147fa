"""A failure prints one line first (what, which file, what to do), rc 2 for bad input,
details in a log file; options and config are validated before any stage runs."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from .conftest import FAST, first_line, run_cli, run_cli_here, snapshot

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


@pytest.mark.parametrize("extra, words", [
    (["--config", "LIST"], "must be a JSON object"),
    (["--formats", "urdf,obj"], "unknown export format(s) obj"),
    (["--stride", "0"], "--stride must be at least 1"),
    (["--max-frames", "0"], "--max-frames must be at least 1"),
])
def test_bad_options_fail_in_one_line_before_any_stage(extra: list[str], words: str, scan: Path, tmp_path: Path) -> None:
    (tmp_path / "list.json").write_text("[1, 2]")
    extra = [str(tmp_path / "list.json") if a == "LIST" else a for a in extra]
    r = run_cli_here(["convert", str(scan), "--out", str(tmp_path / "out"), *extra])
    assert r.returncode == 2, r.stderr[-2000:]
    assert first_line(r.stderr).startswith("react3d convert: error: ") and words in first_line(r.stderr), r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


@pytest.fixture()
def small_fs(tmp_path: Path) -> Iterator[Path]:
    """A 300 KB tmpfs (root only): too small for an output; unmounted afterwards."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    if shutil.which("mount") is None or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(mnt)],
                                                       capture_output=True).returncode != 0:
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], check=False)


def test_disk_full_is_one_line_and_leaves_nothing(small_fs: Path, scan: Path, cli_env: dict, tmp_path: Path) -> None:
    """Disk full used to be a raw traceback with a 642 KB line, after ~100 lines of Prefect errors."""
    env = {**cli_env, "REACT3D_LOG_DIR": str(tmp_path)}
    r = run_cli(["convert", str(scan), "--out", str(small_fs / "out"), *FAST], env)
    assert r.returncode == 1, r.stderr[-2000:]
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "No space left on device" in lines[0] and "details: " in lines[0], r.stderr[-3000:]
    assert max(map(len, lines)) < 600
    log = Path(lines[0].split("details: ")[1].rstrip(")"))
    text = log.read_text()
    assert "ERROR prefect.task_runs" in text and "Traceback" in text  # Prefect's records and the traceback: one file
    assert len([p for p in tmp_path.iterdir() if p.name.startswith("react3d-")]) == 1
    assert list(small_fs.iterdir()) == []  # no half-written output, no staging folder


def test_read_only_output_is_refused_before_anything_runs(small_fs: Path, scan: Path) -> None:
    subprocess.run(["mount", "-o", "remount,ro", str(small_fs)], check=True)
    before = snapshot(small_fs)
    r = run_cli_here(["convert", str(scan), "--out", str(small_fs / "out"), *FAST])
    assert r.returncode == 2, r.stderr[-2000:]
    assert first_line(r.stderr).startswith(f"react3d convert: error: {small_fs / 'out'}: is not writable"), r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and snapshot(small_fs) == before


def test_dataset_failure_is_a_table_row_not_tracebacks(scan: Path, cli_env: dict, tmp_path: Path) -> None:
    root = tmp_path / "data"
    shutil.copytree(scan, root / "good")
    shutil.copytree(scan, root / "broken")
    (root / "broken" / "scans" / "mesh_aligned_0.05.ply").write_bytes(b"ply\nformat ascii 1.0\nelement vertex 3\n")
    env = {**cli_env, "REACT3D_LOG_DIR": str(tmp_path), "COLUMNS": "250"}
    r = run_cli(["convert-dataset", str(root), "--out", str(tmp_path / "out"), *FAST], env)
    assert r.returncode == 1, r.stderr[-3000:]
    assert "Traceback" not in r.stderr and "ERROR" not in r.stderr, r.stderr[-3000:]
    assert "1/2 scenes converted" in r.stdout and "mesh_aligned_0.05.ply" in r.stdout, r.stdout[-3000:]
    assert "details of the failures: " in r.stdout
    assert (tmp_path / "out" / "good" / "scene.json").is_file() and not (tmp_path / "out" / "broken").exists()
