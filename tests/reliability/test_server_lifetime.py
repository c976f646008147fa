"""A killed command leaves no process behind: the local Prefect server that a ``react3d convert`` started
stops itself once no command has used it for the idle period (even after ``kill -9`` of the command),
and the next command still works; Prefect's temporary server of a plain Python run ends with that run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from flows import local_server

from .conftest import FAST, REPO, end_group, isolated_env, run_cli

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

IDLE_S = 3


def _children(pid: int) -> list[tuple[int, str]]:
    out = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            stat = Path(f"/proc/{d}/stat").read_text().rsplit(")", 1)[1].split()
            if int(stat[1]) == pid:
                out.append((int(d), Path(f"/proc/{d}/cmdline").read_text().replace("\0", " ")))
        except (OSError, IndexError):
            pass
    return out


def _running(pid: int) -> bool:
    """Alive and not a zombie (a zombie holds no memory; PID 1 of a container may never reap it)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def _naming(text: str) -> list[int]:
    """Processes whose command line contains ``text``."""
    found = []
    for d in os.listdir("/proc"):
        if d.isdigit() and _running(int(d)):
            try:
                if text in Path(f"/proc/{d}/cmdline").read_text().replace("\0", " "):
                    found.append(int(d))
            except OSError:
                pass
    return found


def _wait_gone(pids: list[int], seconds: float) -> list[int]:
    deadline = time.monotonic() + seconds
    while any(map(_running, pids)) and time.monotonic() < deadline:
        time.sleep(0.2)
    return [p for p in pids if _running(p)]


def test_kill_9_of_convert_leaves_nothing_after_the_idle_period(scan: Path, converted: Path, cli_env: dict,
                                                                prefect_home_copy, tmp_path: Path) -> None:  # noqa: ANN001
    home = prefect_home_copy(tmp_path / "home")  # a migrated database: the server starts in seconds
    env = {**isolated_env(home), local_server.IDLE_ENV: str(IDLE_S)}
    folder = home / local_server.SUBDIR
    cmd = [sys.executable, "-m", "flows.cli", "convert", str(scan), "--out", str(tmp_path / "out"), *FAST]
    p = subprocess.Popen(cmd, cwd=REPO, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
    try:
        started: list[tuple[int, str]] = []
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline and p.poll() is None:
            st = local_server.read_state(folder)
            if st is not None and local_server.healthy(st["url"], timeout=1):  # mid-run: the server serves it
                started = _children(p.pid)
                break
            time.sleep(0.1)
        assert any(local_server.MODULE in c for _, c in started), f"no local server was started: {started}"
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
        left = _wait_gone([pid for pid, _ in started], IDLE_S + 60)
        assert left == [], f"processes the killed command started outlived the idle period: {started}"
        assert _naming(str(home)) == [] and local_server.read_state(folder) is None
    finally:
        end_group(p.pid)  # whatever the outcome, nothing of this test keeps running

    # a later command works (on the run's warm store: what it shows here is the server's part)
    env.update(REACT3D_CACHE=cli_env["REACT3D_CACHE"], PREFECT_LOCAL_STORAGE_PATH=cli_env["PREFECT_LOCAL_STORAGE_PATH"])
    r = run_cli(["convert", str(scan), "--out", str(tmp_path / "again"), *FAST], env)
    assert r.returncode == 0, r.stderr[-3000:]
    assert sum("started a local Prefect server" in ln for ln in r.stdout.splitlines()) == 1
    assert json.loads((tmp_path / "again" / "scene.json").read_text())["objects"]
    server = local_server.read_state(folder)
    assert server is not None and _running(server["pid"])  # it outlives its command ...
    assert _wait_gone([server["pid"]], IDLE_S + 60) == []   # ... for the idle period only
    assert _naming(str(home)) == []


PYTHON_RUN = """
import sys
from prefect import flow
import flows.convert_scene  # routes Prefect's temporary server through flows.server_watchdog

@flow
def nothing() -> None:
    pass

nothing()
"""


def test_kill_9_of_a_python_run_ends_its_temporary_server(tmp_path: Path) -> None:
    """Flows called from Python without a server get Prefect's temporary one; it ends with the caller."""
    env = isolated_env(tmp_path / "home")
    p = subprocess.Popen([sys.executable, "-c", PYTHON_RUN], cwd=REPO, env=env, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        server = None
        deadline = time.monotonic() + 180
        while server is None and time.monotonic() < deadline and p.poll() is None:
            server = next((c for c in _children(p.pid) if "uvicorn" in c[1] or "server_watchdog" in c[1]), None)
            time.sleep(0.05)
        assert server is not None, "no temporary Prefect server was started"
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
        deadline = time.monotonic() + 15
        while _running(server[0]) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _running(server[0]), f"Prefect's server outlived its killed parent: {server[1]}"
    finally:
        end_group(p.pid)
