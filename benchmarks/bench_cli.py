"""Whole-process cost of ``react3d convert``: a first run vs later runs of the same scene to other output
folders, as separate processes, in two settings:

- ``local`` (the default path, nothing started by the user): no ``PREFECT_API_URL``, a fresh
  ``PREFECT_HOME``. The first command starts react3d's local Prefect server (``flows/local_server.py``,
  migrating a new database), later ones reuse it; then one more run after the server was stopped (what
  a user pays when coming back after the idle period). Afterwards no server may be left running.
- ``running``: ``react3d server`` started first and named by ``PREFECT_API_URL``.

Why whole processes: the in-process benchmark hides what a command-line user pays per command
(interpreter and Prefect imports, a server's start, flow-run heartbeats). Fixed cost = wall time minus
the flow's own stage time (``timings.total`` in the manifest).

    python benchmarks/bench_cli.py SCENE [--repeats 3] [--modes local,running] [--args '--max-frames 50']

Uses private PREFECT_HOMEs and REACT3D_CACHEs under --work (cold cache for each first run), prints a
table and writes ``benchmarks/results/cli_overhead_local.json`` (``--json`` for another file).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from _workdir import bench_workdir

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from flows import local_server  # noqa: E402
from tasks.prefect_env import server_reachable  # noqa: E402


def _env(home: Path, api: str | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    env.update(PREFECT_HOME=str(home / "prefect-home"), REACT3D_CACHE=str(home / "cache"),
               PREFECT_LOCAL_STORAGE_PATH=str(home / "prefect-home" / "storage"), PYTHONPATH=str(REPO))
    if api:
        env["PREFECT_API_URL"] = api
    return env


def convert(scene: str, out: Path, env: dict[str, str], extra: list[str]) -> dict[str, Any]:
    """One ``react3d convert`` process: wall time, the flow's stage time, fixed cost, exit code."""
    shutil.rmtree(out, ignore_errors=True)
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "flows.cli", "convert", scene, "--out", str(out), *extra],
                       env=env, cwd=REPO, capture_output=True, text=True)
    wall = time.perf_counter() - t
    row: dict[str, Any] = {"wall_s": round(wall, 2), "rc": p.returncode}
    if p.returncode != 0:
        row["stderr_tail"] = p.stderr[-2000:]
        return row
    timings = json.loads((out / "scene.json").read_text())["timings"]
    row["stage_s"] = round(timings.get("total", 0.0), 2)
    row["fixed_s"] = round(wall - row["stage_s"], 2)
    row["timings"] = {k: round(v, 2) for k, v in timings.items()}
    row["started_server"] = "started a local Prefect server" in p.stdout
    return row


def _med(rows: list[dict[str, Any]], k: str) -> float:
    vals = [r[k] for r in rows if k in r]
    return round(statistics.median(vals), 2) if vals else float("nan")


def bench_local(scene: str, work: Path, repeats: int, extra: list[str]) -> dict[str, Any]:
    """Nothing started by the user: the first command starts the local server, the next ones reuse it."""
    home = work / "local"
    env = _env(home, None)
    first = convert(scene, work / "out-local-first", env, extra)
    again = [convert(scene, work / f"out-local-again-{i}", env, extra) for i in range(repeats)]
    state = local_server.read_state(local_server.folder(home / "prefect-home"))
    local_server.stop_if_unused(home / "prefect-home")  # as if the idle period had passed
    after_idle = convert(scene, work / "out-local-after-idle", env, extra)
    state2 = local_server.read_state(local_server.folder(home / "prefect-home"))
    local_server.stop_if_unused(home / "prefect-home")
    pids = [s["pid"] for s in (state, state2) if s]
    return {"first": first, "again": again, "after_idle_stop": after_idle,
            "servers_started": len(pids), "left_running": [p for p in pids if local_server.alive(p)]}


def bench_running(scene: str, work: Path, repeats: int, extra: list[str], port: int) -> dict[str, Any]:
    """``react3d server`` started by the user and named by PREFECT_API_URL."""
    home = work / "running"
    home.mkdir(parents=True, exist_ok=True)
    if not port:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
    api = f"http://127.0.0.1:{port}/api"
    log = open(home / "server.log", "wb")  # noqa: SIM115 (closed with the server)
    server = subprocess.Popen([sys.executable, "-m", "flows.cli", "server", "--port", str(port)], env=_env(home, None),
                              cwd=REPO, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        t = time.perf_counter()
        while not server_reachable(api, timeout=1):
            if server.poll() is not None or time.perf_counter() - t > 300:
                raise SystemExit(f"react3d server did not come up (see {home / 'server.log'})")
            time.sleep(0.5)
        start = round(time.perf_counter() - t, 1)
        env = _env(home, api)
        first = convert(scene, work / "out-running-first", env, extra)
        again = [convert(scene, work / f"out-running-again-{i}", env, extra) for i in range(repeats)]
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(server.pid, signal.SIGINT)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
        log.close()
    return {"server_start_s": start, "first": first, "again": again}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--modes", default="local,running", help="Comma-separated: local, running.")
    ap.add_argument("--port", type=int, default=0, help="Port of `react3d server` in the running mode (default: a free one).")
    ap.add_argument("--work", type=Path, default=Path("/tmp/react3d-bench-cli"))
    ap.add_argument("--args", default="", help="Extra convert arguments, e.g. '--max-frames 50'.")
    ap.add_argument("--json", type=Path, default=REPO / "benchmarks" / "results" / "cli_overhead_local.json")
    a = ap.parse_args()
    extra = a.args.split()
    modes = [m for m in a.modes.split(",") if m]
    bench_workdir(a.work, fresh=True)
    result: dict[str, Any] = {"scene": a.scene, "args": extra, "cpus": os.cpu_count(), "load_before": os.getloadavg(),
                              "time_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime())}
    if "local" in modes:
        result["local_server"] = bench_local(a.scene, a.work, a.repeats, extra)
    if "running" in modes:
        result["running_server"] = bench_running(a.scene, a.work, a.repeats, extra, a.port)
    result["load_after"] = os.getloadavg()

    summary: dict[str, Any] = {}
    rows: list[tuple[str, dict[str, Any]]] = []
    for key, name in (("local_server", "local"), ("running_server", "running")):
        if key not in result:
            continue
        r = result[key]
        summary[f"{name}_first_wall_s"] = r["first"].get("wall_s")
        summary[f"{name}_again_wall_s_median"] = _med(r["again"], "wall_s")
        summary[f"{name}_again_over_first"] = round(_med(r["again"], "wall_s") / r["first"]["wall_s"], 3)
        summary[f"{name}_again_fixed_s_median"] = _med(r["again"], "fixed_s")
        rows += [(f"first ({name} server)", r["first"])]
        rows += [(f"again #{i + 1} ({name} server)", x) for i, x in enumerate(r["again"])]
        if "after_idle_stop" in r:
            rows.append(("after the idle stop (local)", r["after_idle_stop"]))
            summary["local_after_idle_stop_wall_s"] = r["after_idle_stop"].get("wall_s")
            summary["local_left_running"] = r["left_running"]
    result["summary"] = summary
    print(f"{'run':<30}{'wall s':>9}{'stage s':>9}{'fixed s':>9}")
    for name, r in rows:
        print(f"{name:<30}{r.get('wall_s', float('nan')):>9}{r.get('stage_s', float('nan')):>9}{r.get('fixed_s', float('nan')):>9}")
    print(json.dumps(summary))
    a.json.write_text(json.dumps(result, indent=1))
    print(f"wrote {a.json}")
    return 0 if all(r.get("rc") == 0 for _, r in rows) and not summary.get("local_left_running") else 1


if __name__ == "__main__":
    sys.exit(main())
