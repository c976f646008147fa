"""Issue 20, item 9: a killed ``react3d convert`` does not leave Prefect's temporary server running."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from .conftest import FAST, REPO, end_group


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


def test_kill_9_of_convert_ends_the_temporary_server(scan: Path, cli_env: dict, tmp_path: Path) -> None:
    cmd = [sys.executable, "-m", "flows.cli", "convert", str(scan), "--out", str(tmp_path / "out"), *FAST]
    p = subprocess.Popen(cmd, cwd=REPO, env=cli_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                         start_new_session=True)
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
        end_group(p.pid)  # whatever the outcome, nothing of this test keeps running
