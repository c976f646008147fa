"""Dataset speed-up with more Prefect workers on this machine: the same synthetic dataset converted
through the convert-scene deployment by 1 worker, then by 2 (each run on a fresh server and an empty
store, so nothing is cached), plus the embedded in-process mode for reference.

    python benchmarks/bench_workers.py --scenes 4 --json benchmarks/results/orchestration_workers.json

Wall time is the `react3d convert-dataset` command from submission to the table (server and workers
already up); the load average of the machine is recorded with each run (other jobs share the cores).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from deployments.local_cluster import LocalCluster  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
from _workdir import bench_workdir  # noqa: E402


def make_dataset(root: Path, n: int, frames: int) -> Path:
    """``n`` small procedural dressers (seeds 0..n-1), generated once."""
    from react3d_core.synthetic import generate_scene

    for i in range(n):
        d = root / f"s{i}"
        if not (d / "synth_meta.json").exists():
            generate_scene(d, source="procedural", seed=i, n_frames=frames, kind="dresser")
    return root


def _load() -> float:
    return round(os.getloadavg()[0], 2)


def run_cluster(work: Path, data: Path, workers: int, args: list[str]) -> dict[str, Any]:
    shutil.rmtree(work, ignore_errors=True)
    with LocalCluster(work, n_workers=workers) as c:
        load0, t0 = _load(), time.perf_counter()
        r = c.convert_dataset([str(data), "--out", str(work / "out"), *args], concurrency=2 * workers)
        wall = time.perf_counter() - t0
        rows = c.artifact("dataset-summary") or []
    if r.returncode != 0:
        raise RuntimeError(r.stdout[-2000:] + r.stderr[-2000:])
    return {"mode": f"{workers} worker(s)", "workers": workers, "wall_s": round(wall, 1), "load_before": load0,
            "load_after": _load(), "scenes": [{k: x[k] for k in ("scene", "status", "seconds", "worker")} for x in rows]}


def run_inprocess(work: Path, data: Path, concurrency: int, args: list[str]) -> dict[str, Any]:
    shutil.rmtree(work, ignore_errors=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    env.update({"PREFECT_HOME": str(work / "prefect"), "REACT3D_CACHE": str(work / "cache"), "PYTHONPATH": str(ROOT)})
    load0, t0 = _load(), time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "flows.cli", "convert-dataset", str(data), "--out", str(work / "out"),
                        "--concurrency", str(concurrency), *args], env=env, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(r.stdout[-2000:] + r.stderr[-2000:])
    return {"mode": f"in-process, {concurrency} thread(s) (temporary server start included)", "workers": 0,
            "wall_s": round(wall, 1), "load_before": load0, "load_after": _load()}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", type=int, default=4)
    p.add_argument("--frames", type=int, default=12)
    p.add_argument("--work", type=Path, default=Path("/tmp/react3d-bench-workers"))
    p.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "results" / "orchestration_workers.json")
    p.add_argument("--inprocess", action="store_true", help="Also time the embedded mode with 1 and 2 threads.")
    a = p.parse_args()
    args = ["--perception", "oracle", "--formats", "urdf"]
    bench_workdir(a.work)  # keeps the dataset between runs; w1/w2/ip* below are ours to clear
    data = make_dataset(a.work / "dataset", a.scenes, a.frames)
    result: dict[str, Any] = {"what": f"{a.scenes} procedural dressers, {a.frames} frames, oracle perception, URDF export",
                              "cpus": os.cpu_count(), "runs": [], "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    a.json.parent.mkdir(parents=True, exist_ok=True)
    plan = [lambda: run_cluster(a.work / "w1", data, 1, args), lambda: run_cluster(a.work / "w2", data, 2, args)]
    if a.inprocess:
        plan += [lambda: run_inprocess(a.work / "ip1", data, 1, args), lambda: run_inprocess(a.work / "ip2", data, 2, args)]
    for step in plan:  # written after every run: a later failure keeps the earlier numbers
        try:
            result["runs"].append(step())
        except RuntimeError as exc:
            result["runs"].append({"error": str(exc)[-500:]})
        w = {r.get("workers"): r["wall_s"] for r in result["runs"] if "wall_s" in r}
        if 1 in w and 2 in w:
            result["speedup_2_vs_1_workers"] = round(w[1] / w[2], 2)
        a.json.write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
