"""ScanNet++-sized scene end to end: a >= 1M-face scan with 300 keyframes, heuristic perception, all
three export formats; first run (empty cache) and cached re-run (same scene, another output folder);
wall time and peak memory per stage.

    python benchmarks/bench_scannetpp.py [--faces 1000000] [--frames 300] [--work /tmp/react3d-bench-1m]

The scene is a procedural kitchen (``react3d_core.synthetic``) rendered with ``--frames`` RGB-D frames,
its scan mesh subdivided to ``--faces`` (``benchmarks/scaling.py: densify``). Each run is a separate
process (``--child``): its stages are timed by the flow (manifest ``timings``) and its resident memory
is sampled every 0.1 s and attributed to the stage in progress (the flow's progress callback). Uses the
Prefect server named by PREFECT_API_URL if set, else the temporary one. Prints a table and writes
``benchmarks/results/scannetpp_1m.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))
from _workdir import bench_workdir  # noqa: E402


def child(scene: str, out: str, config: dict[str, Any], report: str) -> None:
    """One timed conversion in this process: stage timings, per-stage peak RSS, process peak RSS."""
    import psutil

    import flows.convert_scene as cs

    proc = psutil.Process()
    current = ["load"]
    peaks: dict[str, float] = {}
    starts: dict[str, float] = {}
    t0 = time.perf_counter()

    def hook(stage: str, done: int, total: int) -> None:
        if stage not in starts:
            starts[stage] = time.perf_counter() - t0
            current[0] = stage

    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            rss = proc.memory_info().rss / 2**20
            peaks[current[0]] = max(peaks.get(current[0], 0.0), rss)
            stop.wait(0.1)

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    manifest = cs.convert_scene(scene, out, config, progress=hook)
    wall = time.perf_counter() - t0
    stop.set()
    th.join()
    m = json.loads(Path(manifest).read_text())
    Path(report).write_text(json.dumps({
        "wall_s": wall, "timings": m["timings"], "stage_start_s": starts, "peak_rss_mb_by_stage": peaks,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "export_sizes": m.get("export_sizes", {}), "n_objects": len(m["objects"]),
    }, indent=1))


def make_scene(scene: Path, frames: int, faces: int, seed: int) -> int:
    """Generate the kitchen once (kept between runs); returns its face count."""
    from react3d_core.data.mesh import load_mesh

    mesh = scene / "scans" / "mesh_aligned_0.05.ply"
    if not mesh.is_file():
        from react3d_core.synthetic import generate_scene
        from scaling import densify

        tmp = scene.with_name(scene.name + ".partial")
        shutil.rmtree(tmp, ignore_errors=True)
        generate_scene(tmp, source="procedural", seed=seed, n_frames=frames, kind="kitchen")
        densify(tmp, faces)
        os.replace(tmp, scene)
    return load_mesh(mesh).n_faces


def run_child(scene: Path, out: Path, config: dict[str, Any], env: dict[str, str]) -> dict[str, Any]:
    report = out.with_suffix(".json")
    shutil.rmtree(out, ignore_errors=True)
    t = time.perf_counter()
    p = subprocess.run([sys.executable, __file__, "--child", str(scene), str(out), json.dumps(config), str(report)],
                       env=env, cwd=REPO, capture_output=True, text=True)
    if p.returncode != 0:
        return {"error": p.stderr[-3000:], "process_wall_s": time.perf_counter() - t}
    r = json.loads(report.read_text())
    r["process_wall_s"] = time.perf_counter() - t
    return r


STAGES = ("load", "perception", "segmentation", "articulation", "assembly", "export", "report")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--faces", type=int, default=1_000_000)
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--work", type=Path, default=Path("/tmp/react3d-bench-1m"))
    ap.add_argument("--formats", default="urdf,usd,mjcf")
    ap.add_argument("--child", nargs=4, metavar=("SCENE", "OUT", "CONFIG", "REPORT"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        from tasks import prefect_env

        prefect_env.configure()
        child(a.child[0], a.child[1], json.loads(a.child[2]), a.child[3])
        return 0
    bench_workdir(a.work)  # keeps the generated scene between runs
    scene = a.work / f"kitchen_s{a.seed}_f{a.frames}_{a.faces // 1000}k"
    t = time.perf_counter()
    n_faces = make_scene(scene, a.frames, a.faces, a.seed)
    gen_s = time.perf_counter() - t
    config = {"perception": {"backend": "heuristic"}, "frames": {"stride": 1},
              "export": {"formats": [f for f in a.formats.split(",") if f]}}
    env = dict(os.environ, REACT3D_CACHE=str(a.work / "cache"), PYTHONPATH=str(REPO))
    shutil.rmtree(a.work / "cache", ignore_errors=True)  # first run: nothing reused
    load = os.getloadavg()
    first = run_child(scene, a.work / "out-first", config, env)
    again = run_child(scene, a.work / "out-again", config, env)
    result = {"scene": str(scene), "faces": n_faces, "frames": a.frames, "config": config, "cpus": os.cpu_count(),
              "load_before": load, "load_after": os.getloadavg(), "generate_s": round(gen_s, 1),
              "prefect_api_url": os.environ.get("PREFECT_API_URL"), "first": first, "again": again}
    print(f"scene: {n_faces} faces, {a.frames} frames, load {load[0]:.1f} (cpus {os.cpu_count()})")
    print(f"{'stage':<14}{'first s':>9}{'first MB':>10}{'again s':>9}{'again MB':>10}")
    for st in STAGES + ("total",):
        row = [st]
        for r in (first, again):
            row += [r.get("timings", {}).get(st, float("nan")), r.get("peak_rss_mb_by_stage", {}).get(st, float("nan"))]
        print(f"{row[0]:<14}{row[1]:>9.1f}{row[2]:>10.0f}{row[3]:>9.1f}{row[4]:>10.0f}")
    for name, r in (("first", first), ("again", again)):
        if "error" in r:
            print(f"{name}: FAILED\n{r['error']}")
        else:
            print(f"{name}: process wall {r['process_wall_s']:.1f} s, peak RSS {r['peak_rss_mb']:.0f} MB, "
                  f"export {r['export_sizes'].get('total', 0) / 1e6:.1f} MB, {r['n_objects']} objects")
    out = REPO / "benchmarks" / "results" / "scannetpp_1m.json"
    out.write_text(json.dumps(result, indent=1))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
