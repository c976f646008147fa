"""Scaling curves: whole-pipeline and per-stage time and peak memory vs frame count and vs mesh faces.

Full run (long, hours on 2 cores):
    python3 benchmarks/scaling.py --frames 75 150 300 600 --faces 100000 500000 1000000 2000000 --out scaling_out
Reduced check:
    python3 benchmarks/scaling.py --frames 30 60 --faces 0 --out /tmp/scaling_small
Faces are raised by midpoint subdivision of the generated scan mesh (original vertex ids are kept,
so the GT vertex sets still index the right points; only timings and memory are reported here).
Writes <out>/scaling.json and <out>/scaling.png.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from flows.bench.runner import run_isolated, run_one  # noqa: E402
from react3d_core.atomic import atomic_path, write_json  # noqa: E402


def densify(scene_dir: Path, target_faces: int) -> int:
    """Subdivide ``scans/mesh_aligned_0.05.ply`` in place until it has >= target faces; returns faces."""
    from react3d_core.data.mesh import TriMesh, load_mesh, save_mesh
    import trimesh.remesh

    path = scene_dir / "scans" / "mesh_aligned_0.05.ply"
    m = load_mesh(path)
    v, f, c = m.vertices, m.faces, m.colors
    while len(f) < target_faces:
        v, f, attrs = trimesh.remesh.subdivide(v, f, vertex_attributes={"color": c.astype(float)})
        c = attrs["color"]  # midpoints get the mean colour of their edge
    save_mesh(path, TriMesh(v, f, c))
    return int(len(f))


def measure(scene_dir: Path, res_dir: Path, config: dict[str, Any], frames: int, faces: int | None) -> dict[str, Any]:
    from react3d_core.data.parts import InteractiveScene

    # cold: an earlier run of the same scene (same content keys) must not turn this into a cache hit
    r = run_isolated(run_one, {"name": scene_dir.name, "scene_dir": str(scene_dir)}, str(res_dir), config,
                     str(res_dir.parent / "cold-cache"))
    timings = InteractiveScene.load(r["manifest"]).timings
    return {"frames": frames, "faces": faces, "wall_s": r["wall_s"], "peak_rss_mb": r["peak_rss_mb"], "stages": timings}


def plot(result: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for col, key in enumerate(("frames", "faces")):
        runs = [r for r in result[f"vs_{key}"] if "error" not in r]
        if not runs:
            continue
        x = [r[key] for r in runs]
        ax = axes[0, col]
        ax.plot(x, [r["wall_s"] for r in runs], "k-o", label="total")
        for st in sorted({s for r in runs for s in r["stages"]}):
            ax.plot(x, [r["stages"].get(st, 0.0) for r in runs], "-", label=st, alpha=0.7)
        ax.set(xlabel=key, ylabel="seconds", title=f"time vs {key}")
        ax.legend(fontsize=7)
        axes[1, col].plot(x, [r["peak_rss_mb"] for r in runs], "b-o")
        axes[1, col].set(xlabel=key, ylabel="peak RSS (MB)", title=f"memory vs {key}")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, nargs="+", default=[75, 150, 300, 600])
    ap.add_argument("--faces", type=int, nargs="+", default=[100_000, 500_000, 1_000_000, 2_000_000],
                    help="Target faces (0 = skip the faces sweep).")
    ap.add_argument("--faces-frames", type=int, default=75, help="Frames of the scene used for the faces sweep.")
    ap.add_argument("--seed", type=int, default=100)
    ap.add_argument("--kind", default="kitchen")
    ap.add_argument("--perception", default="oracle", choices=("oracle", "heuristic", "models"))
    ap.add_argument("--formats", default="urdf,usd,mjcf", help="Export formats ('none' to time the pipeline without export).")
    ap.add_argument("--out", default="scaling_out")
    args = ap.parse_args(argv)
    from react3d_core.synthetic import generate_scene

    out = Path(args.out)
    # every generated frame is used (stride 1): the frame axis is the number of frames processed
    config = {"perception": {"backend": args.perception}, "frames": {"stride": 1},
              "export": {"formats": [f for f in args.formats.split(",") if f and f != "none"]}}
    result: dict[str, Any] = {"config": config, "seed": args.seed, "kind": args.kind, "vs_frames": [], "vs_faces": []}
    for n in args.frames:
        sd = out / "scenes" / f"f{n}"
        if not (sd / "scans").is_dir():
            generate_scene(sd, source="procedural", seed=args.seed, n_frames=n, kind=args.kind)
        try:
            result["vs_frames"].append(measure(sd, out / "results" / f"f{n}", config, n, None))
        except Exception as exc:  # noqa: BLE001 - keep the other points
            result["vs_frames"].append({"frames": n, "error": f"{exc.__class__.__name__}: {exc}"})
        print(result["vs_frames"][-1], flush=True)
    for target in [t for t in args.faces if t > 0]:
        base = out / "scenes" / f"f{args.faces_frames}_base"
        if not (base / "scans").is_dir():
            generate_scene(base, source="procedural", seed=args.seed, n_frames=args.faces_frames, kind=args.kind)
        sd = out / "scenes" / f"faces{target}"
        if not sd.is_dir():
            shutil.copytree(base, sd)
        nf = densify(sd, target)
        try:
            result["vs_faces"].append(measure(sd, out / "results" / f"faces{target}", config, args.faces_frames, nf))
        except Exception as exc:  # noqa: BLE001
            result["vs_faces"].append({"faces": nf, "error": f"{exc.__class__.__name__}: {exc}"})
        print(result["vs_faces"][-1], flush=True)
    write_json(out / "scaling.json", result)
    plot(result, out / "scaling.png")
    print(f"wrote {out / 'scaling.json'} and {out / 'scaling.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
