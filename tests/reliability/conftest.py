"""Real-process fixtures for the reliability suite: the ``react3d`` CLI run as a subprocess with a
private Prefect home and object store, on a small synthetic scan (8 frames)."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def scan(synthetic_scene: Callable[..., Path]) -> Path:
    """A small synthetic dresser (8 frames, ground truth); read-only, copy it before changing it."""
    return synthetic_scene(seed=0, n_frames=8, kind="dresser")


@pytest.fixture(scope="session")
def cli_env(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """Environment of the CLI subprocesses: a private PREFECT_HOME and cache shared by this session."""
    home = tmp_path_factory.mktemp("rel-prefect")
    env = {**os.environ, "PREFECT_HOME": str(home), "REACT3D_CACHE": str(home / "cache"),
           "PREFECT_LOCAL_STORAGE_PATH": str(home / "storage"), "PYTHONPATH": str(REPO)}
    for k in ("PREFECT_API_URL", "REACT3D_DEBUG"):
        env.pop(k, None)
    return env


FAST = ["--perception", "oracle", "--formats", "none", "--stride", "1"]


def run_cli(args: list[str], env: dict[str, str], timeout: float = 240) -> subprocess.CompletedProcess[str]:
    """``python3 -m flows.cli ARGS`` in its own session; any child it leaves (Prefect's server) is ended."""
    p = subprocess.Popen([sys.executable, "-m", "flows.cli", *args], cwd=REPO, env=env, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    finally:
        end_group(p.pid)
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


def end_group(pgid: int) -> None:
    """End the process group this suite started (its leader's pid), if anything of it is still running."""
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def first_line(text: str) -> str:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    return lines[0] if lines else ""


def snapshot(root: Path) -> dict[str, str]:
    """Every path under ``root`` (hidden ones too) with the sha256 of its bytes ('dir' for folders)."""
    out: dict[str, str] = {}
    for p in sorted(root.rglob("*")):
        rel = p.relative_to(root).as_posix()
        if p.is_symlink():
            out[rel] = "link:" + os.readlink(p)
        elif p.is_dir():
            out[rel] = "dir"
        else:
            out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


@pytest.fixture(scope="session")
def converted(scan: Path, cli_env: dict[str, str], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One finished conversion of ``scan`` (read-only; copy it to use it as a previous output)."""
    out = tmp_path_factory.mktemp("rel-converted") / "out"
    r = run_cli(["convert", str(scan), "--out", str(out), *FAST], cli_env)
    assert r.returncode == 0, r.stderr[-3000:]
    return out


def isolated_env(home: Path) -> dict[str, str]:
    """Environment of a CLI run with nothing of the user's Prefect or react3d settings: its own Prefect
    home, result storage and object store under ``home``."""
    e = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    e.update(PREFECT_HOME=str(home), PREFECT_LOCAL_STORAGE_PATH=str(home / "storage"),
             REACT3D_CACHE=str(home / "react3d-cache"), PYTHONPATH=str(REPO),
             PREFECT_SERVER_EPHEMERAL_STARTUP_TIMEOUT_SECONDS="300")
    return e


def convert_oracle_urdf(scene: Path, out: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """``react3d convert`` with oracle perception (fast, deterministic) and URDF export, in its own
    process group; whatever the group leaves running (Prefect's temporary server) is ended afterwards."""
    return run_cli(["convert", str(scene), "--out", str(out), "--perception", "oracle", "--stride", "2",
                    "--formats", "urdf"], env, timeout=900)
