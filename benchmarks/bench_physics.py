"""Physics check over benchmark sets: convert each scene, then drive every joint and probe every cavity and
front in MuJoCo, PyBullet and SAPIEN (react3d_core.physics; definitions in docs/physics.md).

    python3 benchmarks/bench_physics.py --sets demo,heldout,large_kitchens,redkitchen \\
        --perception oracle,heuristic --work /tmp/physics_bench --json benchmarks/results/physics.json

Sets: ``demo`` (the built-in demo kitchen, converted with the heuristic as `react3d demo` does), any set
of benchmarks/sets (``heldout``, ``large_kitchens``, ...; converted with each ``--perception`` backend),
``redkitchen`` (the real scan at /work/shared/data/redkitchen, heuristic). ``--outputs`` checks finished
conversion folders instead. Each conversion writes URDF and MJCF (USD is not driven here) with the
convert-time check switched off; the check then runs in a fresh process per scene, engines one after
another. Prints one row per set, backend and engine (joints, share reaching >= 90 % of the limit,
share passing, deepest penetration, unstable joints, probes), the issue's goal per row, and every
failure with its cause; the JSON holds all of it per joint.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

REDKITCHEN = Path("/work/shared/data/redkitchen")
GOAL = {"reach_share": 0.95, "max_penetration_m": 0.01}
"""Done when: >= 95 % of joints reach >= 90 % of their limit in each engine, penetration <= 1 cm, nothing
unstable, every cavity free and every front blocked."""


def convert_config(backend: str, synthetic: bool) -> dict[str, Any]:
    cfg: dict[str, Any] = {"perception": {"backend": backend}, "export": {"formats": ["urdf", "mjcf"]},
                           "physics": {"enabled": False}}
    if synthetic:
        cfg["frames"] = {"stride": 1}  # synthetic captures are already sparse (as react3d demo / bench)
    return cfg


def entries_for(set_name: str, work: Path, backends: list[str], limit: int | None,
                names: set[str] | None) -> list[dict[str, Any]]:
    """``[{set, backend, name, scene_dir, config}]`` to convert."""
    from flows.bench.runner import load_spec

    if set_name == "demo":
        from react3d_core.synthetic import demo_scene

        scene = work / "scenes" / "demo"
        if not (scene / "synth_meta.json").exists():
            demo_scene(scene)
        rows = [{"name": "demo", "scene_dir": str(scene), "synthetic": True, "backends": ["heuristic"]}]
    elif set_name == "redkitchen":
        rows = [{"name": "redkitchen", "scene_dir": str(REDKITCHEN), "synthetic": False, "backends": ["heuristic"]}]
    else:
        rows = [{**e, "synthetic": "source" in e, "backends": backends} for e in load_spec(set_name, work)]
    if names:
        rows = [r for r in rows if r["name"] in names]
    rows = rows[:limit] if limit else rows
    out = []
    for r in rows:
        for b in r.pop("backends"):
            out.append({**r, "set": set_name, "backend": b, "config": convert_config(b, r["synthetic"])})
    return out


def convert(entry: dict[str, Any], work: Path, reuse: bool) -> Path:
    from flows.bench.runner import run_isolated, run_one

    res = work / "results" / entry["set"] / entry["backend"] / entry["name"]
    if reuse and (res / "scene.json").is_file():
        return res
    run_isolated(run_one, entry, str(res), entry["config"])
    return res


def check_one(out: str, engines: tuple[str, ...]) -> dict[str, Any]:
    """Child body: the check of one output folder, as JSON."""
    from react3d_core.physics import check_output

    return check_output(out, engines=engines).model_dump(mode="json")


def failures(check: dict[str, Any]) -> list[dict[str, Any]]:
    """Every failed joint, probe and engine of one scene, with its cause."""
    out = []
    for e in check["engines"]:
        if e["status"] == "error":
            out.append({"engine": e["engine"], "what": "engine", "cause": e["reason"]})
        for j in e["joints"]:
            if not j["passed"]:
                out.append({"engine": e["engine"], "what": f"joint {j['joint']}", "object": j["object_id"],
                            "cause": "; ".join(j["causes"])})
        for p in e["probes"]:
            if not p["passed"]:
                out.append({"engine": e["engine"], "what": f"{p['kind']} probe", "object": p["object_id"], "cause": p["cause"]})
    return out


def aggregate(checks: list[dict[str, Any]], engine: str, reach: float = 0.9) -> dict[str, Any]:
    """Pooled over the scenes of one set and backend, for one engine."""
    es = [e for c in checks for e in c["engines"] if e["engine"] == engine]
    ok = [e for e in es if e["status"] == "ok"]
    joints = [j for e in ok for j in e["joints"]]
    probes = [p for e in ok for p in e["probes"]]
    n = len(joints)
    cav = [p for p in probes if p["kind"] == "cavity"]
    fr = [p for p in probes if p["kind"] == "front"]
    row = {
        "scenes": len(es), "ran": len(ok), "errors": sum(e["status"] == "error" for e in es),
        "skipped": sum(e["status"] == "skipped" for e in es),
        "joints": n,
        "reached": sum(j["reached"] >= reach for j in joints),
        "passed": sum(j["passed"] for j in joints),
        "penetration_ok": sum(j["penetration"] <= GOAL["max_penetration_m"] for j in joints),
        "max_penetration": max((j["penetration"] for j in joints), default=0.0),
        "unstable": sum(j["unstable"] is not None for j in joints),
        "cavities": len(cav), "cavities_free": sum(p["passed"] for p in cav),
        "fronts": len(fr), "fronts_blocked": sum(p["passed"] for p in fr),
        "rest_contacts": sum((e["rest"] or {}).get("moving_contacts", 0) for e in ok),
        "seconds": sum(e["seconds"] for e in es),
        "cpu_seconds": sum(e.get("cpu_seconds", 0.0) for e in es),
    }
    row["reach_share"] = row["reached"] / n if n else None
    row["pass_share"] = row["passed"] / n if n else None
    row["goal_met"] = bool(n and row["ran"] == row["scenes"] and row["reached"] >= GOAL["reach_share"] * n
                           and row["penetration_ok"] == n and row["unstable"] == 0
                           and row["cavities_free"] == row["cavities"] and row["fronts_blocked"] == row["fronts"])
    return row


def print_report(result: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console(width=max(Console().width, 160))
    t = Table(title="physics check over benchmark sets")
    for c in ("set", "backend", "engine", "scenes", "joints", "reach >= 90 %", "pass", "max pen.", "unstable", "cavities free",
              "fronts blocked", "rest contacts", "cpu s", "goal"):
        t.add_column(c, justify="left" if c in ("set", "backend", "engine") else "right")

    def pct(a: int, n: int) -> str:
        return f"{a}/{n} ({100 * a / n:.0f} %)" if n else "–"

    for key, block in result["sets"].items():
        s, b = key.split("/")
        for engine, a in block["aggregate"].items():
            t.add_row(s, b, engine, f"{a['ran']}/{a['scenes']}", str(a["joints"]), pct(a["reached"], a["joints"]),
                      pct(a["passed"], a["joints"]), f"{100 * a['max_penetration']:.1f} cm", str(a["unstable"]),
                      f"{a['cavities_free']}/{a['cavities']}", f"{a['fronts_blocked']}/{a['fronts']}", str(a["rest_contacts"]),
                      f"{a['cpu_seconds']:.0f}", "[green]met[/]" if a["goal_met"] else "[red]not met[/]")
    console.print(t)
    for key, block in result["sets"].items():
        for sc in block["scenes"]:
            if sc.get("error"):
                console.print(f"[red]{key} {sc['name']}[/]: {sc['error']}")
            for f in sc.get("failures", []):
                obj = f" ({f['object']})" if f.get("object") else ""
                console.print(f"{key} {sc['name']} {f['engine']} {f['what']}{obj}: {f['cause']}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sets", default="demo,heldout,large_kitchens,redkitchen")
    p.add_argument("--perception", default="oracle,heuristic", help="Backends for benchmark sets (demo and RedKitchen: heuristic).")
    p.add_argument("--engines", default="mujoco,pybullet,sapien")
    p.add_argument("--work", default="/tmp/react3d_physics_bench", help="Work folder (scenes, conversions).")
    p.add_argument("--json", default=None, help="Result JSON (default WORK/physics.json).")
    p.add_argument("--limit", type=int, default=None, help="At most this many scenes per set.")
    p.add_argument("--scenes", default=None, help="Only these scene names (comma-separated).")
    p.add_argument("--reuse", action="store_true", help="Check conversions already in WORK instead of converting again.")
    p.add_argument("--outputs", nargs="*", default=None, help="Check these finished conversion folders (set 'outputs').")
    args = p.parse_args(argv)

    from benchmarks._workdir import bench_workdir
    from flows.bench.runner import run_isolated
    from react3d_core.atomic import write_json

    work = bench_workdir(Path(args.work))
    engines = tuple(e.strip() for e in args.engines.split(",") if e.strip())
    backends = [b.strip() for b in args.perception.split(",") if b.strip()]
    names = {n.strip() for n in args.scenes.split(",")} if args.scenes else None
    jobs: list[tuple[str, str, str, Path | None, dict[str, Any] | None]] = []
    if args.outputs:
        jobs += [("outputs", "as-converted", Path(o).name, Path(o), None) for o in args.outputs]
    else:
        for s in (x.strip() for x in args.sets.split(",") if x.strip()):
            jobs += [(e["set"], e["backend"], e["name"], None, e) for e in entries_for(s, work, backends, args.limit, names)]
    result: dict[str, Any] = {"created": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "engines": list(engines), "goal": GOAL, "sets": {}}
    t0 = time.perf_counter()
    for set_name, backend, name, out, entry in jobs:
        block = result["sets"].setdefault(f"{set_name}/{backend}", {"scenes": [], "aggregate": {}})
        row: dict[str, Any] = {"name": name}
        try:
            if out is None:
                t = time.perf_counter()
                out = convert(entry, work, args.reuse)  # type: ignore[arg-type]
                row["convert_s"] = time.perf_counter() - t
            row["output"] = str(out)
            check = run_isolated(check_one, str(out), engines)
            row["summary"] = {e["engine"]: {k: v for k, v in e.items() if k not in ("joints", "probes", "rest")}
                              for e in check["engines"]}
            row["check"] = check
            row["failures"] = failures(check)
        except Exception as exc:  # noqa: BLE001 - one scene failing must not stop the benchmark
            row["error"] = f"{type(exc).__name__}: {str(exc).strip()[:400]}"
        block["scenes"].append(row)
        print(f"{set_name}/{backend} {name}: " + (row.get("error") or f"{len(row['failures'])} failures"), flush=True)
    for block in result["sets"].values():
        checks = [sc["check"] for sc in block["scenes"] if "check" in sc]
        block["aggregate"] = {e: aggregate(checks, e) for e in engines}
    result["seconds"] = time.perf_counter() - t0
    print_report(result)
    write_json(args.json or work / "physics.json", result)
    print(f"json: {args.json or work / 'physics.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
