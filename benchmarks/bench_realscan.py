"""Real-scan benchmark: convert 7-Scenes RedKitchen and score it against hand-drawn front boxes.

    python3 benchmarks/bench_realscan.py [--scene ../shared/data/redkitchen] [--out /tmp/rk_out]
        [--perception heuristic] [--stride N] [--json benchmarks/results/redkitchen_stride5.json]
    python3 benchmarks/bench_realscan.py --perception-level [--stride N] [--heuristic JSON] --json F

The scan has no 3D ground truth; ``tests/data/redkitchen_fronts.json`` holds 2D boxes of its 9 clearly
visible fronts in a few colour frames (drawn by hand). ``react3d convert`` runs as its own process (``python -m
flows.cli convert`` from the checkout holding this script, so a clean export of a commit benchmarks that
commit), timed end to end (wall) with the peak resident memory of its process tree sampled every
0.2 s (and the largest single process from the kernel's rusage). The result folder is then scored with
``react3d_core.metrics.box_labels`` (occlusion-aware projection of every part, Hungarian matching, a
front is found at mean box IoU >= 0.5). The scan itself is read from outside the repository and never
copied into it.

``--perception-level`` skips ``react3d convert``: the heuristic perception is built in this process on the
selected frames and every front it finds is scored as a part (its faces' vertices, its joint). Minutes
instead of a whole conversion, for deciding thresholds and comparing view sets or mesh variants; report
acceptance numbers with the full conversion.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

DEFAULT_SCENE = (ROOT / ".." / "shared" / "data" / "redkitchen").resolve()
DEFAULT_LABELS = ROOT / "tests" / "data" / "redkitchen_fronts.json"


def _tree_rss(pid: int) -> int:
    """Summed RSS (bytes) of a process and all its descendants; 0 once it is gone."""
    import psutil

    try:
        p = psutil.Process(pid)
        procs = [p, *p.children(recursive=True)]
    except psutil.NoSuchProcess:
        return 0
    total = 0
    for q in procs:
        try:
            total += q.memory_info().rss
        except psutil.NoSuchProcess:
            pass
    return total


def run_convert(scene: Path, out: Path, perception: str = "heuristic", stride: int | None = None,
                extra: list[str] | None = None, cold_cache: bool = True) -> dict[str, Any]:
    """Run ``react3d convert`` as a subprocess; wall time, exit code, peak tree RSS and the log tail.

    ``cold_cache`` points the task cache (``REACT3D_CACHE``) at an empty temporary folder: a re-run with
    a warm cache skips perception and would time the cache, not the pipeline."""
    cmd = [sys.executable, "-m", "flows.cli", "convert", str(scene), "--out", str(out), "--perception", perception]
    if stride is not None:
        cmd += ["--stride", str(stride)]
    cmd += list(extra or [])  # `python -m flows.cli` from this checkout: the code benchmarked is the tree the script is in
    peak = [0]
    t0 = time.perf_counter()
    env = dict(os.environ)
    tmp_cache = tempfile.mkdtemp(prefix="react3d_bench_cache_") if cold_cache else None
    if tmp_cache:
        env["REACT3D_CACHE"] = tmp_cache
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT, env=env)
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], _tree_rss(proc.pid))
            done.wait(0.2)

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    log, _ = proc.communicate()
    wall = time.perf_counter() - t0
    done.set()
    th.join()
    if tmp_cache:
        shutil.rmtree(tmp_cache, ignore_errors=True)
    max_child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024  # Linux: KiB
    return {"cmd": cmd, "returncode": proc.returncode, "wall_s": round(wall, 2),
            "peak_tree_rss_mb": round(peak[0] / 2**20, 1), "peak_single_process_rss_mb": round(max_child / 2**20, 1),
            "cold_cache": cold_cache, "log_tail": log[-3000:]}


def manifest_facts(out: Path) -> dict[str, Any]:
    """Frames used, timings and config recorded in the converted scene's manifest."""
    m = json.loads((out / "scene.json").read_text())
    frames_cfg = m.get("config", {}).get("frames", {})
    return {"timings": m.get("timings", {}), "frames_config": frames_cfg, "n_objects": len(m.get("objects", []))}


def perception_parts(scene_dir: Path, stride: int | None, overrides: dict[str, Any]) -> tuple[list[Any], dict[str, Any]]:
    """The heuristic's fronts on ``scene_dir`` as scored parts (no conversion): built on the frames the
    config selects (``stride`` None: the default keyframes), each front's faces' vertices and its joint."""
    import numpy as np

    from react3d_core.config import PipelineConfig
    from react3d_core.metrics.box_labels import PredictedPart
    from react3d_core.perception.heuristic import HeuristicModel
    from react3d_core.scene_io import load_scene

    cfg = PipelineConfig().with_overrides({"perception": {"heuristic": overrides}, "frames": {"stride": stride}})
    t0 = time.perf_counter()
    scene = load_scene(scene_dir, cfg.frames)
    t1 = time.perf_counter()
    model = HeuristicModel(scene, cfg.perception.heuristic)
    t2 = time.perf_counter()
    parts = []
    for k, f in enumerate(model.fronts):
        a = f.articulation
        v = model.mesh.vertices[np.unique(model.mesh.faces[f.faces].ravel())]
        parts.append(PredictedPart(f"front_{k:03d}", v, a.joint_type if a is not None else "unknown",
                                   tuple(float(x) for x in a.axis) if a is not None else None))
    facts = {"frames_used": len(scene.frames), "load_s": round(t1 - t0, 2), "perception_s": round(t2 - t1, 2),
             "n_faces": int(model.mesh.n_faces)}
    if model.image is not None:
        c = model.image.calibration
        facts["calibration"] = {"scale": float(c.scale), "dx": float(c.dx), "dy": float(c.dy)}
    return parts, facts


def score_perception_level(scene_dir: Path, labels: Path, stride: int | None, overrides: dict[str, Any],
                           iou: float = 0.5) -> dict[str, Any]:
    """``perception_parts`` scored against the box labels (the same matching as a converted scene)."""
    from react3d_core.metrics.box_labels import load_box_labels, match_boxes, part_boxes
    from react3d_core.scene_io import load_scene

    parts, facts = perception_parts(scene_dir, stride, overrides)
    lab = load_box_labels(labels)
    full = load_scene(scene_dir)  # the labelled frames need not be among those selected
    report = match_boxes(part_boxes(parts, full, lab), lab, iou)
    by_id = {p.object_id: p for p in parts}
    for fr in report.fronts:
        if fr.part is not None:
            fr.joint_type, fr.joint_class = by_id[fr.part].joint_type, by_id[fr.part].joint_class
    return {"perception_level": facts, "evaluation": report.to_dict()}


def print_table(report: dict[str, Any]) -> None:
    """Front id, matched part, mean box IoU, joint; then the totals."""
    print(f"{'front':6} {'part':10} {'box IoU':>8} {'other':>6} {'joint':22} found")
    for f in report["fronts"]:
        print(f"{f['front_id']:6} {f['part'] or '-':10} {f['iou']:8.2f} {f['other_iou']:6.2f} "
              f"{(f['joint_class'] or '-'):22} {'yes' if f['found'] else 'no'}")
    print(f"found {report['n_found']}/{report['n_fronts']} fronts; {report['n_parts']} parts, "
          f"{report['n_false_parts']} false {report['false_parts']}, ignored {report['ignored_parts']}, "
          f"unseen {report['unseen_parts']}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", type=Path, default=DEFAULT_SCENE)
    ap.add_argument("--labels", type=Path, default=DEFAULT_LABELS)
    ap.add_argument("--out", type=Path, default=Path("/tmp/react3d_redkitchen"))
    ap.add_argument("--perception", default="heuristic")
    ap.add_argument("--stride", type=int, default=None, help="use every n-th frame (default: the config's)")
    ap.add_argument("--iou", type=float, default=0.5, help="box IoU for a front to count as found")
    ap.add_argument("--note", default="", help="free text stored in the JSON (e.g. which commit an export holds)")
    ap.add_argument("--warm-cache", action="store_true", help="keep the user's task cache (default: an empty one)")
    ap.add_argument("--skip-convert", action="store_true", help="score an existing --out folder only")
    ap.add_argument("--perception-level", action="store_true",
                    help="no conversion: score the heuristic's fronts directly (see module docstring)")
    ap.add_argument("--heuristic", default="{}", help="with --perception-level: JSON overrides of perception.heuristic")
    ap.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "results" / "redkitchen.json")
    args = ap.parse_args(argv)
    if not args.scene.is_dir():
        print(f"scene folder not found: {args.scene}", file=sys.stderr)
        return 2
    if args.perception_level:
        res = score_perception_level(args.scene, args.labels, args.stride, json.loads(args.heuristic), args.iou)
        result = {"scene": str(args.scene), "stride": args.stride, "heuristic": json.loads(args.heuristic),
                  "note": args.note, "source": _git_state(), **res}
        print(f"perception level: {res['perception_level']}")
        print_table(res["evaluation"])
        _write(args.json, result)
        print(f"wrote {args.json}")
        return 0

    from react3d_core.metrics.box_labels import evaluate_box_labels
    from react3d_core.scene_io import load_scene

    result: dict[str, Any] = {"scene": args.scene.name, "perception": args.perception, "stride": args.stride, "note": args.note,
                              "source": _git_state(),
                              "machine": {"python": platform.python_version(), "cpus": _cpus(),
                                          "load_avg_1m_before": round(os.getloadavg()[0], 2)}}
    if not args.skip_convert:
        run = run_convert(args.scene, args.out, args.perception, args.stride, cold_cache=not args.warm_cache)
        print(f"convert: rc={run['returncode']} wall {run['wall_s']} s, peak RSS {run['peak_tree_rss_mb']} MB "
              f"(tree), {run['peak_single_process_rss_mb']} MB (largest process)")
        result["convert"] = run
        if run["returncode"] != 0:
            print(run["log_tail"], file=sys.stderr)
            _write(args.json, result)
            return 1
    facts = manifest_facts(args.out)
    from react3d_core.config import FrameSelectionConfig
    from react3d_core.scene_io import select_frames

    scene = load_scene(args.scene)
    n_total = len(scene.frames)
    facts["frames_used"] = len(select_frames(scene.frames, FrameSelectionConfig(**facts["frames_config"])))
    facts["frames_available"] = n_total
    result["manifest"] = facts
    t0 = time.perf_counter()
    report = evaluate_box_labels(args.out, scene, args.labels, iou_threshold=args.iou)
    result["eval_s"] = round(time.perf_counter() - t0, 2)
    result["evaluation"] = report.to_dict()
    print(f"frames used {facts['frames_used']} of {n_total}; stage timings (s) {facts['timings']}")
    print_table(result["evaluation"])
    _write(args.json, result)
    print(f"wrote {args.json}")
    return 0


def _git_state() -> dict[str, Any]:
    """Commit of the benchmarked checkout and whether it had local changes (a benchmark of a dirty tree is not a commit's)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                               text=True, check=True).stdout.strip()
        return {"commit": head, "modified_files": len(dirty.splitlines())}
    except (OSError, subprocess.CalledProcessError):
        return {"commit": None, "modified_files": None}


def _cpus() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 0)


def _write(path: Path, data: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=2) + "\n")


if __name__ == "__main__":
    raise SystemExit(main())
