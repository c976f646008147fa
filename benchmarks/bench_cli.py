"""Whole-process cost of ``react3d convert``: first run vs a second run of the same scene to another
output folder, with a running Prefect server (``react3d server``) and with the temporary one.

Why whole processes: the in-process benchmark hides what a command-line user pays per command
(interpreter and Prefect imports, the temporary server's start and stop, flow-run heartbeats).
Fixed cost = wall time minus the flow's own stage time (``timings.total`` in the manifest).

    python benchmarks/bench_cli.py SCENE [--repeats 3] [--port 4201]

Uses a private PREFECT_HOME and REACT3D_CACHE under --work (cold cache for the first run), prints a
table and writes ``benchmarks/results/cli_overhead.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from _workdir import bench_workdir

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from tasks.prefect_env import server_reachable  # noqa: E402


def _env(work: Path, api: str | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    env.update(PREFECT_HOME=str(work / "prefect-home"), REACT3D_CACHE=str(work / "cache"),
               PREFECT_LOCAL_STORAGE_PATH=str(work / "prefect-home" / "storage"), PYTHONPATH=str(REPO))
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
    row["temporary_note"] = "temporary Prefect server" in p.stdout
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--port", type=int, default=4201)
    ap.add_argument("--work", type=Path, default=Path("/tmp/react3d-bench-cli"))
    ap.add_argument("--args", default="", help="Extra convert arguments, e.g. '--max-frames 50'.")
    ap.add_argument("--no-temporary", action="store_true", help="Skip the runs with the temporary server.")
    a = ap.parse_args()
    extra = a.args.split()
    bench_workdir(a.work, fresh=True)
    api = f"http://127.0.0.1:{a.port}/api"
    load = os.getloadavg()
    server = subprocess.Popen([sys.executable, "-m", "flows.cli", "server", "--port", str(a.port)], env=_env(a.work, None),
                              cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    result: dict[str, Any] = {"scene": a.scene, "args": extra, "cpus": os.cpu_count(), "load_before": load}
    try:
        t = time.perf_counter()
        while not server_reachable(api, timeout=1):
            if server.poll() is not None or time.perf_counter() - t > 180:
                raise SystemExit("react3d server did not come up")
            time.sleep(0.5)
        result["server_start_s"] = round(time.perf_counter() - t, 1)
        env = _env(a.work, api)
        first = convert(a.scene, a.work / "out-first", env, extra)
        again = [convert(a.scene, a.work / f"out-again-{i}", env, extra) for i in range(a.repeats)]
        result["running_server"] = {"first": first, "again": again}
    finally:
        os.killpg(server.pid, signal.SIGINT)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
    if not a.no_temporary:
        env = _env(a.work, None)
        result["temporary_server"] = {"again": [convert(a.scene, a.work / f"out-tmp-{i}", env, extra) for i in range(a.repeats)]}
    result["load_after"] = os.getloadavg()

    def med(rows: list[dict[str, Any]], k: str) -> float:
        vals = [r[k] for r in rows if k in r]
        return round(statistics.median(vals), 2) if vals else float("nan")

    rs = result["running_server"]
    result["summary"] = {
        "first_wall_s": rs["first"].get("wall_s"), "again_wall_s_median": med(rs["again"], "wall_s"),
        "again_over_first": round(med(rs["again"], "wall_s") / rs["first"]["wall_s"], 3),
        "fixed_s_median_running_server": med(rs["again"], "fixed_s"),
    }
    if "temporary_server" in result:
        result["summary"]["again_wall_s_median_temporary"] = med(result["temporary_server"]["again"], "wall_s")
        result["summary"]["fixed_s_median_temporary"] = med(result["temporary_server"]["again"], "fixed_s")
    print(f"{'run':<28}{'wall s':>9}{'stage s':>9}{'fixed s':>9}")
    rows = [("first (running server)", rs["first"])] + [(f"again #{i + 1} (running server)", r) for i, r in enumerate(rs["again"])]
    rows += [(f"again #{i + 1} (temporary server)", r) for i, r in enumerate(result.get("temporary_server", {}).get("again", []))]
    for name, r in rows:
        print(f"{name:<28}{r.get('wall_s', float('nan')):>9}{r.get('stage_s', float('nan')):>9}{r.get('fixed_s', float('nan')):>9}")
    print(json.dumps(result["summary"]))
    out = REPO / "benchmarks" / "results" / "cli_overhead.json"
    out.write_text(json.dumps(result, indent=1))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
