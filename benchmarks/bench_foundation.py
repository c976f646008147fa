"""Foundation benchmark: rasterization throughput and synthetic-scene generation time.

    python3 benchmarks/bench_foundation.py --frames 300 --edge 0.012 --json bench_foundation.json

Measures (on the machine it runs on): Rasterizer.render frames/s at 960x720 and 256x192 on the
generated scan mesh, and the wall time to generate a scene (build + render RGB, depth, part ids +
write). Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from react3d_core.atomic import write_json  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--frames", type=int, default=300)
    p.add_argument("--edge", type=float, default=0.012, help="furniture triangle size (0.012 m gives > 300k faces)")
    p.add_argument("--kind", default="kitchen")
    p.add_argument("--raster-frames", type=int, default=30)
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)

    from rich.console import Console
    from rich.table import Table

    from react3d_core.data.mesh import load_mesh
    from react3d_core.raster import Rasterizer
    from react3d_core.scene_io import load_scene
    from react3d_core.synthetic import generate_scene

    rows: dict[str, float | int | str] = {}
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        root = generate_scene(Path(d) / "scene", seed=0, n_frames=a.frames, kind=a.kind, edge=a.edge)
        rows["synth_s"] = time.perf_counter() - t0
        scene = load_scene(root)
        mesh = load_mesh(scene.mesh_path)
        rows["faces"] = mesh.n_faces
        rows["frames"] = len(scene.frames)
        t0 = time.perf_counter()
        r = Rasterizer(mesh)
        rows["bvh_build_s"] = time.perf_counter() - t0
        frames = scene.frames[: a.raster_frames]
        for name, width in (("raster_960x720_fps", 960), ("raster_256x192_fps", 256)):
            t0 = time.perf_counter()
            for _ in r.render_frames(frames, width=width):
                pass
            rows[name] = len(frames) / (time.perf_counter() - t0)
    rows["synth_s_per_frame"] = float(rows["synth_s"]) / int(rows["frames"])
    table = Table(title="foundation benchmark")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for k, v in rows.items():
        table.add_row(k, f"{v:.3f}" if isinstance(v, float) else str(v))
    Console().print(table)
    if a.json:
        write_json(a.json, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
