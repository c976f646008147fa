"""Command-line overhead (issue 18): a running Prefect server named by PREFECT_API_URL is reused (no
temporary server, the run is in its history); without one the command says in one line (stdout: stderr
holds errors only) that it starts a temporary server; a PREFECT_API_URL that does not answer is a one-line error before anything runs."""

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

from tasks.prefect_env import server_reachable

from .conftest import REPO, end_group, first_line, isolated_env, run_cli

FAST = ["--perception", "oracle", "--formats", "none", "--stride", "2"]
NOTE = "starting a temporary Prefect server"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_unreachable_api_url_is_one_line_before_anything_runs(scan: Path, tmp_path: Path) -> None:
    env = isolated_env(tmp_path / "home")
    env["PREFECT_API_URL"] = f"http://127.0.0.1:{_free_port()}/api"
    out = tmp_path / "out"
    t = time.perf_counter()
    r = run_cli(["convert", str(scan), "--out", str(out), *FAST], env, timeout=120)
    assert r.returncode == 2, r.stderr[-2000:]
    line = first_line(r.stderr)
    assert line.startswith("react3d convert: error: PREFECT_API_URL=") and "react3d server" in line
    assert "Traceback" not in r.stderr and not out.exists()
    assert time.perf_counter() - t < 60  # no Prefect client retries


def test_running_server_is_reused_and_temporary_one_is_announced(scan: Path, tmp_path: Path) -> None:
    env = isolated_env(tmp_path / "home")
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
        assert NOTE not in r.stdout + r.stderr
        req = urllib.request.Request(api + "/flow_runs/filter", data=b"{}", method="POST",
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=10) as resp:
            runs = json.loads(resp.read())
        assert [x["state_type"] for x in runs] == ["COMPLETED"]  # the run is in the server's history
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
    r = run_cli(["convert", str(scan), "--out", str(tmp_path / "b"), *FAST], env)
    assert r.returncode == 0, r.stderr[-3000:]
    assert sum(NOTE in ln for ln in r.stdout.splitlines()) == 1 and NOTE not in r.stderr
