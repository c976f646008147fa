"""Command-line overhead: a running Prefect server named by PREFECT_API_URL is reused (nothing started,
the run is in its history); without one the first command starts react3d's local server and says so in
one line (stdout: stderr holds errors only), and the next command reuses it silently (both runs in its
history); a PREFECT_API_URL that does not answer is a one-line error before anything runs."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from flows import local_server
from tasks.prefect_env import server_reachable

from .conftest import FAST, REPO, end_group, first_line, isolated_env, run_cli, run_cli_here

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

NOTE = "started a local Prefect server"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_unreachable_api_url_is_one_line_before_anything_runs(scan: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    t = time.perf_counter()
    r = run_cli_here(["convert", str(scan), "--out", str(out), *FAST],
                     {"PREFECT_API_URL": f"http://127.0.0.1:{_free_port()}/api"})
    assert r.returncode == 2, r.stderr[-2000:]
    line = first_line(r.stderr)
    assert line.startswith("react3d convert: error: PREFECT_API_URL=") and "react3d server" in line
    assert "Traceback" not in r.stderr and not out.exists()
    assert time.perf_counter() - t < 60  # no Prefect client retries


def _runs(api: str) -> list[str]:
    req = urllib.request.Request(api + "/flow_runs/filter", data=b"{}", method="POST",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as resp:
        return [x["state_type"] for x in json.loads(resp.read())]


def test_running_server_is_reused_and_local_one_is_announced(scan: Path, converted: Path, cli_env: dict,
                                                             prefect_home_copy, tmp_path: Path) -> None:  # noqa: ANN001
    home = prefect_home_copy(tmp_path / "home")
    env = isolated_env(home)  # its own Prefect home; the run's warm store (the scan is converted: only servers differ)
    env.update(REACT3D_CACHE=cli_env["REACT3D_CACHE"], PREFECT_LOCAL_STORAGE_PATH=cli_env["PREFECT_LOCAL_STORAGE_PATH"])
    port = _free_port()
    api = f"http://127.0.0.1:{port}/api"
    server = subprocess.Popen([sys.executable, "-m", "flows.cli", "server", "--port", str(port)], cwd=REPO, env=env,
                              text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        t = time.perf_counter()
        while not server_reachable(api, timeout=1):
            assert server.poll() is None, server.stdout.read() if server.stdout else ""
            assert time.perf_counter() - t < 240, "react3d server did not answer"
            time.sleep(0.5)
        r = run_cli(["convert", str(scan), "--out", str(tmp_path / "a"), *FAST], {**env, "PREFECT_API_URL": api})
        assert r.returncode == 0, r.stderr[-3000:]
        assert NOTE not in r.stdout + r.stderr and local_server.read_state(home / local_server.SUBDIR) is None
        assert _runs(api) == ["COMPLETED"]  # the run is in the server's history
        # `react3d server` again: it sees the running one and says how to use it, instead of a port clash
        again = subprocess.run([sys.executable, "-m", "flows.cli", "server", "--port", str(port)], cwd=REPO, env=env,
                               capture_output=True, text=True, timeout=120)
        assert again.returncode == 0 and f"export PREFECT_API_URL={api}" in again.stdout
    finally:
        os.killpg(server.pid, signal.SIGINT)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            pass
        end_group(server.pid)
    folder = home / local_server.SUBDIR
    try:
        r = run_cli(["convert", str(scan), "--out", str(tmp_path / "b"), *FAST], env)
        assert r.returncode == 0, r.stderr[-3000:]
        assert sum(NOTE in ln for ln in r.stdout.splitlines()) == 1 and NOTE not in r.stderr
        first = local_server.read_state(folder)
        assert first is not None and first["url"].startswith("http://127.0.0.1:")
        r = run_cli(["convert", str(scan), "--out", str(tmp_path / "c"), *FAST], env)
        assert r.returncode == 0, r.stderr[-3000:]
        assert NOTE not in r.stdout + r.stderr  # reused, silently
        assert local_server.read_state(folder) == first
        assert _runs(first["url"]) == ["COMPLETED", "COMPLETED", "COMPLETED"]  # one history: `react3d server`'s too
        stop = subprocess.run([sys.executable, "-m", "flows.cli", "server", "--stop"], cwd=REPO, env=env,
                              capture_output=True, text=True, timeout=120)
        assert stop.returncode == 0 and f"stopped the local server at {first['url']}" in stop.stdout, stop
        assert not local_server.alive(first["pid"]) and local_server.read_state(folder) is None
    finally:
        assert local_server.stop_if_unused(home)
