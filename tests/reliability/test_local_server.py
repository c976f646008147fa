"""react3d's local Prefect server (flows/local_server.py): leases die with their holder, two commands
starting at once end up with one server, a stale state file is replaced, and the server leaves once
unused."""

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

from .conftest import REPO, isolated_env

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

HOLD = """
import fcntl, os, sys, time
fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT)
fcntl.flock(fd, fcntl.LOCK_SH)
print("held", flush=True)
time.sleep(600)
"""


def test_a_lease_ends_with_its_holder_even_after_kill_9(tmp_path: Path) -> None:
    lease = tmp_path / "lease-1"
    assert local_server.lease_free(lease)
    p = subprocess.Popen([sys.executable, "-c", HOLD, str(lease)], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout is not None and p.stdout.readline().strip() == "held"
        assert not local_server.lease_free(lease)
        assert not local_server.lease_free(lease)  # checking does not take it away
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
        assert local_server.lease_free(lease)
    finally:
        p.kill()


CONNECT = """
import json, sys
from flows import local_server
s = local_server.connect(sys.argv[1])
s.wait_ready()
print(json.dumps({"url": s.url, "pid": s.pid, "started": s.started}), flush=True)
"""


def test_two_commands_starting_at_once_share_one_server_that_replaced_a_stale_one(prefect_home_copy,  # noqa: ANN001
                                                                                 tmp_path: Path) -> None:
    home = prefect_home_copy(tmp_path / "home")
    folder = local_server.folder(home)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (folder / "state.json").write_text(json.dumps({"pid": dead.pid, "url": "http://127.0.0.1:9/api", "started": 0}))
    env = {**isolated_env(home), local_server.IDLE_ENV: "2"}
    procs = [subprocess.Popen([sys.executable, "-c", CONNECT, str(home)], cwd=REPO, env=env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), [err[-2000:] for _, err in outs]
    seen = [json.loads(out) for out, _ in outs]
    try:
        assert seen[0]["url"] == seen[1]["url"] and seen[0]["pid"] == seen[1]["pid"] != dead.pid
        assert sorted(s["started"] for s in seen) == [False, True]  # one started it, the other reused it
        state = local_server.read_state(folder)
        assert state is not None and state["pid"] == seen[0]["pid"]  # the stale record was replaced
        deadline = time.monotonic() + 90  # both have exited: unused, it stops after 2 s (+ its shutdown)
        while local_server.alive(state["pid"]) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not local_server.alive(state["pid"]) and local_server.read_state(folder) is None
        assert not local_server.healthy(state["url"], timeout=1)
    finally:
        local_server.stop_if_unused(home)
