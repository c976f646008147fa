"""Run Prefect's temporary API server (uvicorn) so that it ends with the process that started it.

Flows called from Python with no server configured make Prefect 3 start ``python -m uvicorn ...`` and
stop it at exit; a killed process (kill -9, OOM killer, a closed terminal) left it running, reparented
to PID 1, ~200 MB each. :func:`install` makes Prefect start it through this module, which watches its
parent and shuts the server down when the parent is gone. (``react3d`` commands use the shared local
server of ``flows.local_server`` instead, and skip this.)

Usage (by :func:`install` only): ``python -m flows.server_watchdog PARENT_PID UVICORN_ARGS...``.
"""

from __future__ import annotations

import os
import runpy
import signal
import subprocess
import sys
import threading
import time
import types
from typing import Any

POLL_S = 0.5
GRACE_S = 5.0  # after SIGTERM, uvicorn gets this long to shut down before the process exits hard


def _watch(parent: int) -> None:
    """Poll the parent; once it is gone (we were reparented), stop uvicorn, then exit hard if it hangs."""
    while os.getppid() == parent:
        time.sleep(POLL_S)
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(GRACE_S)
    os._exit(1)


def main(argv: list[str]) -> None:
    parent = int(argv[0])
    if os.getppid() != parent:  # the parent died before we started
        sys.exit(1)
    threading.Thread(target=_watch, args=(parent,), name="react3d-parent-watchdog", daemon=True).start()
    sys.argv = ["uvicorn", *argv[1:]]
    runpy.run_module("uvicorn", run_name="__main__", alter_sys=True)


def _popen(args: Any, **kwargs: Any) -> subprocess.Popen[Any]:
    """``subprocess.Popen`` as Prefect's server module sees it: ``python -m uvicorn`` goes through main()."""
    if isinstance(args, list) and args[1:3] == ["-m", "uvicorn"]:
        from tasks.prefect_env import TEMPORARY_NOTE

        # the one line saying where the seconds go; stdout, beside the progress bar: stderr is for errors
        # only (a failed command prints exactly one line there)
        print(TEMPORARY_NOTE, flush=True)
        args = [args[0], "-m", "flows.server_watchdog", str(os.getpid()), *args[3:]]
        env = dict(kwargs.get("env") or os.environ)
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
        kwargs["env"] = env
    return subprocess.Popen(args, **kwargs)


def install() -> bool:
    """Route Prefect's temporary server through the watchdog (only the module that starts it is
    affected); False when this Prefect has no such server class."""
    from prefect.settings import get_current_settings

    from . import local_server

    # a real server, or a command that will use the local one: nothing temporary to watch (and no import cost)
    if get_current_settings().api.url or local_server.planned():
        return False
    try:
        from prefect.server.api import server as srv
    except ImportError:
        return False
    if not hasattr(srv, "SubprocessASGIServer"):
        return False
    if getattr(srv.subprocess, "_react3d_watchdog", False):
        return True
    proxy = types.ModuleType("subprocess")
    proxy.__dict__.update(subprocess.__dict__)
    proxy.Popen = _popen  # type: ignore[attr-defined]
    proxy._react3d_watchdog = True  # type: ignore[attr-defined]
    srv.subprocess = proxy  # type: ignore[attr-defined]
    return True


if __name__ == "__main__":
    main(sys.argv[1:])
