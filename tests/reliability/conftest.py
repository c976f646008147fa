"""Real-process fixtures for the reliability suite: the ``react3d`` CLI run as a subprocess with a
private object store, using the run's shared local Prefect server (``prefect_server``) as a user's
command would find it, on a small synthetic scan (8 frames); cases refused before anything runs are
run in-process (:func:`run_cli_here`)."""

from __future__ import annotations

import hashlib
import os
import shutil
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
def cli_env(tmp_path_factory: pytest.TempPathFactory, prefect_server) -> dict[str, str]:  # noqa: ANN001
    """Environment of the CLI subprocesses: the run's Prefect home (its local server is reused, as by a
    user's second command), a private cache and result storage shared by this session."""
    home = tmp_path_factory.mktemp("rel-prefect")
    env = {**os.environ, "PREFECT_HOME": str(prefect_server.home), "REACT3D_CACHE": str(home / "cache"),
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


def run_cli_here(args: list[str], env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """``react3d ARGS`` in this process, for a command that must refuse before it starts anything: the
    same exit code and output as :func:`run_cli`, without a new interpreter and its imports. ``env``:
    variables set for the call (Prefect's settings are re-read). A command that gets as far as using a
    Prefect server fails the test."""
    import contextlib
    import io

    import prefect.context

    from flows import local_server
    from flows.cli import main

    def started(*_a: object, **_k: object) -> None:
        raise AssertionError(f"react3d {' '.join(args)} went on to use Prefect instead of refusing")

    saved = local_server.attach, local_server.ready, local_server._planned
    saved_env = {k: os.environ.get(k) for k in env or {}}
    local_server.attach = local_server.ready = started  # type: ignore[assignment]
    out, err = io.StringIO(), io.StringIO()
    try:
        os.environ.update(env or {})
        prefect.context.refresh_global_settings_context()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(args)
    finally:
        local_server.attach, local_server.ready, local_server._planned = saved
        for k, v in saved_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        prefect.context.refresh_global_settings_context()
    return subprocess.CompletedProcess(["react3d", *args], rc, out.getvalue(), err.getvalue())


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


def isolated_env(home: Path, prefect_home: Path | None = None) -> dict[str, str]:
    """Environment of a CLI run with nothing of the user's Prefect or react3d settings: its own result
    storage and object store under ``home``, and Prefect home ``prefect_home`` (the run's shared one,
    whose server it then reuses) or ``home`` (a server of its own)."""
    e = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    e.update(PREFECT_HOME=str(prefect_home or home), PREFECT_LOCAL_STORAGE_PATH=str(home / "storage"),
             REACT3D_CACHE=str(home / "react3d-cache"), PYTHONPATH=str(REPO),
             PREFECT_SERVER_EPHEMERAL_STARTUP_TIMEOUT_SECONDS="300")
    return e


def convert_oracle_urdf(scene: Path, out: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """``react3d convert`` with oracle perception (fast, deterministic) and URDF export, in its own
    process group; whatever the group leaves running (Prefect's temporary server) is ended afterwards."""
    return run_cli(["convert", str(scene), "--out", str(out), "--perception", "oracle", "--stride", "2",
                    "--formats", "urdf"], env, timeout=900)


@pytest.fixture(scope="session")
def dresser_first_run(synthetic_scene: Callable[..., Path], shared_cache_dir: Path, prefect_server) -> Path:  # noqa: ANN001
    """One cold ``convert_oracle_urdf`` of the 12-frame dresser (seed 5) with a private store, done once
    per test run (across workers): ``<dir>/home`` (object store and Prefect result records) and
    ``<dir>/out``. Copy it (:func:`copy_first_run`) to start from a finished first run."""
    from filelock import FileLock

    d = shared_cache_dir / "dresser-first-run"
    with FileLock(str(d) + ".lock"):
        if not (d / ".complete").exists():
            shutil.rmtree(d, ignore_errors=True)
            env = isolated_env(d / "home", prefect_server.home)
            first = convert_oracle_urdf(synthetic_scene(seed=5, n_frames=12, kind="dresser"), d / "out", env)
            assert first.returncode == 0, first.stderr[-3000:]
            (d / ".complete").write_text("ok")
    return d


def copy_first_run(first_run: Path, home: Path, out: Path, prefect_home: Path) -> dict[str, str]:
    """A private copy of :func:`dresser_first_run` (store and records under ``home``, its output at ``out``):
    what a second ``convert`` finds after a first one; returns the environment that uses it."""
    shutil.copytree(first_run / "home", home, symlinks=True)
    shutil.copytree(first_run / "out", out, symlinks=True)
    return isolated_env(home, prefect_home)
