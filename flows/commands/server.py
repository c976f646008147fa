"""``react3d server``: a Prefect server of your own (fixed port, no idle stop) that commands use through
``PREFECT_API_URL``; ``react3d server --stop`` stops react3d's local server (the one commands start by
themselves without ``PREFECT_API_URL``, ``flows/local_server.py``) unless a command is using it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

HELP = "Start a local Prefect server (UI, run history) that react3d commands reuse when PREFECT_API_URL points to it."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--host", default="127.0.0.1", help="Address to listen on (default: this machine only).")
    p.add_argument("--port", type=int, default=4200, help="Port (default: Prefect's 4200).")
    p.add_argument("--stop", action="store_true",
                   help="Instead: stop the local server that commands started in this PREFECT_HOME (unless one is using it).")


def run(args: argparse.Namespace) -> int:
    from tasks import prefect_env

    prefect_env.configure()  # quiet defaults (analytics off, server logs CRITICAL) unless the user set them
    if args.stop:
        return _stop()
    url = f"http://{args.host}:{args.port}/api"
    hint = f"export PREFECT_API_URL={url}"
    if prefect_env.server_reachable(url, timeout=1.0):
        print(f"react3d server: a Prefect server already answers at {url}; in your shell: {hint}")
        return 0
    print(f"react3d server: Prefect server with its UI at http://{args.host}:{args.port} (Ctrl-C stops it); "
          f"in other shells: {hint}", flush=True)
    env = {k: v for k, v in os.environ.items() if k != "PREFECT_API_URL"}  # the server itself must not be a client
    cmd = [sys.executable, "-m", "prefect", "server", "start", "--host", args.host, "--port", str(args.port)]
    try:
        return subprocess.call(cmd, env=env)
    except KeyboardInterrupt:  # Ctrl-C reached the server too (same process group): it shuts down
        return 0


def _stop() -> int:
    from prefect.settings import get_current_settings

    from flows import local_server

    home = get_current_settings().home
    st = local_server.read_state(local_server.folder(home))
    if st is None or not local_server.is_server(st["pid"]):
        print(f"react3d server: no local server runs for PREFECT_HOME={home}")
        return 0
    if not local_server.stop_if_unused(home):
        print(f"react3d server: the local server at {st['url']} is in use by a command; it stops by itself once unused")
        return 1
    print(f"react3d server: stopped the local server at {st['url']}")
    return 0
