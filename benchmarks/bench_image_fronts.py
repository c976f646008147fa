"""What the image path of the heuristic costs per frame: the heuristic built with and without it.

    python3 benchmarks/bench_image_fronts.py [SCENE ...] [--stride 5] [--register] [--heuristic JSON] [--json benchmarks/results/image_fronts_cost.json]

Without SCENE it measures a synthetic TSDF kitchen (960x720 photo frames, made in a temporary
folder) and, when present, the real RedKitchen scan (640x480). Each scene is built twice in one
process (mesh-only heuristic, then mesh + images) after a warm-up read of the frames; the added cost
per frame is (t_image - t_mesh) / frames. ``--register`` measures the image path with the opt-in
per-view colour registration on (``registration.sigmas_px`` 12, 6, 3, 1.5); ``--heuristic`` takes JSON overrides
of ``perception.heuristic`` for the mesh + images build (opt-in rules). Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
REDKITCHEN = ROOT.parent / "shared" / "data" / "redkitchen"


REGISTER_SIGMAS = (12.0, 6.0, 3.0, 1.5)


def measure(scene_dir: Path, stride: int, register: bool = False, overrides: dict | None = None) -> dict:
    from react3d_core.config import FrameSelectionConfig
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic import HeuristicModel
    from react3d_core.scene_io import load_scene
    from react3d_core.scene_io.images import frame_rgb

    scene = load_scene(scene_dir, FrameSelectionConfig(stride=stride))
    for f in scene.frames:  # warm the page cache: both runs read the same files
        frame_rgb(f)
    t0 = time.perf_counter()
    mesh_only = HeuristicModel(scene, HeuristicConfig(image={"enabled": False}))
    t1 = time.perf_counter()
    over = dict(overrides or {})
    if register:
        over["registration"] = {**over.get("registration", {}), "sigmas_px": REGISTER_SIGMAS}
    both = HeuristicModel(scene, HeuristicConfig(**over) if over else None)
    t2 = time.perf_counter()
    n = len(scene.frames)
    w, h = scene.frames[0].intrinsics.width, scene.frames[0].intrinsics.height
    return {"scene": str(scene_dir), "frames": n, "size": f"{w}x{h}", "faces": mesh_only.mesh.n_faces,
            "mesh_only_s": round(t1 - t0, 2), "with_images_s": round(t2 - t1, 2),
            "added_s_per_frame": round((t2 - t1 - (t1 - t0)) / max(n, 1), 3),
            "fronts_mesh_only": len(mesh_only.fronts), "fronts_with_images": len(both.fronts),
            "planes": len(both.image.planes) if both.image else 0,
            "colour_scale": round(float(both.image.calibration.scale), 3) if both.image else None,
            "per_view_registration": register, "heuristic_overrides": overrides or {}}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", type=Path)
    ap.add_argument("--stride", type=int, default=5)
    ap.add_argument("--register", action="store_true", help="Image path with the opt-in per-view colour registration.")
    ap.add_argument("--heuristic", default="{}", help="JSON overrides of perception.heuristic for the image build.")
    ap.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "results" / "image_fronts_cost.json")
    args = ap.parse_args()
    import os

    scenes = list(args.scenes)
    tmp = None
    if not scenes:
        from react3d_core.synthetic import generate_scene

        tmp = tempfile.TemporaryDirectory()
        scenes.append(generate_scene(Path(tmp.name) / "kitchen_tsdf", seed=0, kind="kitchen", n_frames=60, mesh="tsdf"))
        if REDKITCHEN.is_dir():
            scenes.append(REDKITCHEN)
    overrides = json.loads(args.heuristic)
    rows = [measure(s, args.stride, args.register, overrides) for s in scenes]
    print(f"{'scene':32} {'frames':>6} {'size':>8} {'faces':>8} {'mesh s':>7} {'+img s':>7} {'s/frame':>8} {'fronts':>9}")
    for r in rows:
        print(f"{Path(r['scene']).name[:32]:32} {r['frames']:6d} {r['size']:>8} {r['faces']:8d} {r['mesh_only_s']:7.2f} "
              f"{r['with_images_s']:7.2f} {r['added_s_per_frame']:8.3f} {r['fronts_mesh_only']:4d}->{r['fronts_with_images']:<4d}")
    out = {"cores": os.cpu_count(), "stride": args.stride, "per_view_registration": args.register,
           "heuristic_overrides": overrides, "rows": rows}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(out, indent=2))
    print(f"wrote {args.json}")
    if tmp is not None:
        tmp.cleanup()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
