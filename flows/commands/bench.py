"""``react3d bench --scenes SPEC``: benchmark a scene set (the runner is ``flows.bench.runner``)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

HELP = "Benchmark a scene set: convert each scene, time it, measure peak memory, evaluate against GT."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scenes", required=True,
                   help="A set file (flows/bench/sets/NAME.json, or just NAME) or a glob of scene folders.")
    p.add_argument("--perception", choices=("oracle", "heuristic", "models"), default="heuristic")
    p.add_argument("--no-refine", action="store_true", help="Disable axis/origin refinement (ablation).")
    p.add_argument("--json", dest="json_path", help="Write the metrics JSON here.")
    p.add_argument("--out", default="bench_out", help="Work folder: generated scenes, results, reports.")
    p.add_argument("--frames", type=int, help="Override the set's frame count for generated scenes.")
    p.add_argument("--formats", default=None,
                   help="Export formats (default: the config's urdf,usd,mjcf; 'none' skips export for accuracy-only runs).")
    p.add_argument("--stride", type=int, default=1,
                   help="Frame stride (default 1: synthetic captures are already sparse; use 5 for raw ScanNet++ iPhone).")
    p.add_argument("--cold", action="store_true",
                   help="Convert every scene with an empty cache (first-run timings; nothing reused from earlier runs).")
    p.add_argument("--no-miss-causes", dest="miss_causes", action="store_false",
                   help="Skip the miss-cause breakdown (it re-runs perception and segmentation traced, after the timed conversion).")


def run(args: argparse.Namespace) -> int:
    from flows.bench.runner import load_spec, print_table, run_bench
    from react3d_core.atomic import write_json

    out_dir = Path(args.out)
    entries = load_spec(args.scenes, out_dir, args.frames)
    config: dict[str, Any] = {"perception": {"backend": args.perception}, "frames": {"stride": args.stride}}
    if args.formats:
        config["export"] = {"formats": [f.strip() for f in args.formats.split(",") if f.strip() and f.strip() != "none"]}
    if args.no_refine:
        config["articulation"] = {"refine": False}
    result = run_bench(entries, out_dir, config, cold=args.cold, miss_causes=args.miss_causes)
    print_table(result)
    write_json(args.json_path or out_dir / "bench.json", result)
    return 0 if not result["failed"] else 1
