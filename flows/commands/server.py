"""``react3d server``: a local Prefect server that later commands reuse through ``PREFECT_API_URL``.

Without one, each ``react3d convert`` starts and stops Prefect's temporary server (and imports its
modules): seconds of fixed cost per command. With one running, a command only connects.
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


def run(args: argparse.Namespace) -> int:
    from tasks import prefect_env

    prefect_env.configure()  # quiet defaults (analytics off, server logs CRITICAL) unless the user set them
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
