"""Orchestration benchmark: one scene through the Prefect flow, first run and cached re-run.

    python3 benchmarks/bench_orchestration.py --frames 300 --json bench_orchestration.json

Reports the same pipeline called directly (``react3d_core.pipeline.convert``, no Prefect), then through the
flow (first run), then the cached re-run; Prefect overhead = flow wall - direct wall (negative when
the flow's parallel fan-out wins), per-stage wall times as the flow measured them. Uses a private
PREFECT_HOME / REACT3D_CACHE under --work.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def run_direct(scene: str, out: Path, cfg: dict) -> float:
    """The same pipeline without Prefect: ``react3d_core.pipeline.convert`` (same step functions, no store)."""
    from react3d_core.pipeline import convert

    t0 = time.perf_counter()
    convert(scene, out, cfg)
    return time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--frames", type=int, default=300)
    p.add_argument("--kind", default="kitchen")
    p.add_argument("--perception", default="oracle", choices=["oracle", "heuristic"])
    p.add_argument("--formats", default="urdf")
    p.add_argument("--work", default="/tmp/react3d-bench-orch")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)
    work = Path(a.work)
    (work / "prefect").mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("PREFECT_HOME", str(work / "prefect"))
    os.environ.setdefault("REACT3D_CACHE", str(work / "cache"))
    from tasks import prefect_env

    prefect_env.configure()
    from rich.console import Console
    from rich.table import Table

    import tasks.articulation as ta
    import tasks.perception as tp
    import tasks.segmentation as tsg
    from flows.convert_scene import convert_scene
    from react3d_core.atomic import write_json
    from react3d_core.data.parts import InteractiveScene
    from react3d_core.synthetic import generate_scene

    scene = work / f"scene_{a.kind}_{a.frames}"
    if not (scene / "synth_meta.json").exists():
        generate_scene(scene, seed=100, n_frames=a.frames, kind=a.kind)
    cfg = {"perception": {"backend": a.perception}, "frames": {"stride": 1},
           "export": {"formats": [f for f in a.formats.split(",") if f and f != "none"]}}
    direct = run_direct(str(scene), work / "direct", cfg)
    from prefect import flow

    flow(lambda: None, name="warm-up")()  # the temporary server is up before timing, like a deployment's
    t0 = time.perf_counter()
    manifest = convert_scene(str(scene), str(work / "out1"), cfg)
    first = time.perf_counter() - t0
    stages = dict(InteractiveScene.load(manifest).timings)
    executed: list[str] = []
    for mod, name in ((tp, "perceive_body"), (tsg, "segment_body"), (ta, "articulate_body")):
        real = getattr(mod, name)
        setattr(mod, name, lambda *x, _r=real, _n=name, **k: (executed.append(_n), _r(*x, **k))[1])
    t0 = time.perf_counter()
    convert_scene(str(scene), str(work / "out2"), cfg)
    cached = time.perf_counter() - t0
    rows = {"frames": a.frames, "direct_s": direct, "flow_first_run_s": first, "prefect_overhead_s": first - direct,
            "prefect_overhead_fraction": (first - direct) / first, "cached_rerun_s": cached,
            "cached_fraction": cached / first, "bodies_executed_on_rerun": len(executed), "stages_s": stages}
    t = Table(title=f"orchestration, {a.frames} frames ({a.perception})")
    t.add_column("metric")
    t.add_column("value", justify="right")
    for k, v in rows.items():
        if isinstance(v, dict):
            for kk, vv in v.items():
                t.add_row(f"{k}.{kk}", f"{vv:.2f}")
        else:
            t.add_row(k, f"{v:.3f}" if isinstance(v, float) else str(v))
    Console().print(t)
    if a.json:
        write_json(a.json, rows)
    print(json.dumps({k: v for k, v in rows.items() if not isinstance(v, dict)}, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
