"""Fusion benchmark: segment_parts on oracle masks of a large synthetic scene, per sub-stage.

    python3 benchmarks/bench_fusion.py --json bench_fusion.json
    python3 benchmarks/bench_fusion.py --scene /path/to/scene --frames 75,150,300 --no-decimate-row

Generates (once, cached) a 300-frame kitchen with furniture triangles of 1.2 cm (> 300k faces),
makes oracle masks (default realism) for every frame, then runs ``segment_parts`` on the first
75 / 150 / 300 frames (evenly spread) in a fresh process each, and reports wall time per sub-stage,
process CPU seconds (user + sys: a shared, loaded machine inflates wall time, not CPU time), the
1-minute load average, peak RSS of that process (sampled every 20 ms; it holds the masks bit-packed and unpacks them on
access, as a store-backed mapping would), candidates and vertex-IoU recall/precision. A last row
runs 75 frames without decimation (``decimate_faces=None``) to show whether decimation pays off.
Mask generation is not part of the fusion time.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import sys
import threading
import time
from collections import Counter
from collections.abc import Iterator, Mapping
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from react3d_core.atomic import write_json  # noqa: E402

CACHE = Path(os.environ.get("REACT3D_BENCH_CACHE", "/tmp/react3d-bench-fusion"))


class PackedMasks(Mapping):
    """frame id -> list[Mask2D], stored bit-packed and unpacked on access (bounded memory)."""

    def __init__(self, packed: dict[str, list[tuple[np.ndarray, tuple[int, int]]]]) -> None:
        self.packed = packed

    def __getitem__(self, fid: str):  # noqa: ANN204
        from react3d_core.data.masks import Mask2D

        return [Mask2D(frame_id=fid, mask=np.unpackbits(b, count=h * w).astype(bool).reshape(h, w))
                for b, (h, w) in self.packed[fid]]

    def __iter__(self) -> Iterator[str]:
        return iter(self.packed)

    def __len__(self) -> int:
        return len(self.packed)


def scene_and_masks(scene: Path | None, n_frames: int, edge: float) -> tuple[Path, Path]:
    """The scene folder and a cache of its oracle masks (npz of packed bits + a seen-count json)."""
    from react3d_core.config import PerceptionConfig
    from react3d_core.perception.oracle import OracleModel
    from react3d_core.scene_io import load_scene
    from react3d_core.synthetic import generate_scene

    if scene is None:
        scene = CACHE / f"kitchen-{n_frames}-{edge}"
        if not (scene / ".complete").exists():
            t = time.perf_counter()
            generate_scene(scene, source="procedural", seed=0, n_frames=n_frames, kind="kitchen", edge=edge)
            (scene / ".complete").write_text("ok")
            print(f"generated {scene} in {time.perf_counter() - t:.1f} s")
    cache = CACHE / f"masks-{scene.name}.npz"
    if not cache.exists():
        s = load_scene(scene)
        model = OracleModel(s, PerceptionConfig(backend="oracle").oracle)
        arrays, seen = {}, Counter()
        t = time.perf_counter()
        for f in s.frames:
            for i, m in enumerate(model.masks(f)):
                arrays[f"{f.frame_id}/{i}"] = np.packbits(m.mask.ravel())
                arrays[f"{f.frame_id}/{i}/shape"] = np.array(m.mask.shape)
            seen.update(pid for pid, _ in model.visible_movable(model.part_image(f)))
        CACHE.mkdir(parents=True, exist_ok=True)
        np.savez(cache, **arrays)
        cache.with_suffix(".seen.json").write_text(json.dumps({str(k): v for k, v in seen.items()}))
        print(f"oracle masks for {len(s.frames)} frames in {time.perf_counter() - t:.1f} s")
    return scene, cache


def run_one(scene: str, cache: str, n: int, decimate: bool, out: mp.Queue) -> None:
    """One configuration in a fresh process: time segment_parts, sample peak RSS."""
    import psutil

    from react3d_core.config import PipelineConfig
    from react3d_core.data import load_mesh
    from react3d_core.fusion import segment_parts
    from react3d_core.metrics.segmentation_quality import segmentation_quality
    from react3d_core.ground_truth import read_articulate3d
    from react3d_core.perception.oracle import make_oracle
    from react3d_core.raster import Rasterizer
    from react3d_core.scene_io import load_scene

    s = load_scene(scene)
    idx = np.unique(np.linspace(0, len(s.frames) - 1, n).round().astype(int))
    s = s.model_copy(update={"frames": tuple(s.frames[i] for i in idx)})
    z = np.load(cache)
    packed: dict[str, list] = {f.frame_id: [] for f in s.frames}
    for k in z.files:
        parts = k.split("/")
        if len(parts) == 2 and parts[0] in packed:
            packed[parts[0]].append((z[k], tuple(int(x) for x in z[k + "/shape"])))
    masks = PackedMasks(packed)
    seen = {int(k): v * n / 300 for k, v in json.loads(Path(cache).with_suffix(".seen.json").read_text()).items()}
    cfg = PipelineConfig().with_overrides({"perception": {"backend": "oracle"},
                                           "fusion": {} if decimate else {"decimate_faces": None}})
    mesh = load_mesh(s.mesh_path)
    perc = make_oracle(s, cfg.perception)
    proc = psutil.Process()
    base = proc.memory_info().rss
    peak = [base]
    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            peak[0] = max(peak[0], proc.memory_info().rss)
            time.sleep(0.02)

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    timings: dict[str, float] = {}
    cpu0 = proc.cpu_times()
    t = time.perf_counter()
    rast = Rasterizer(mesh)
    timings["bvh"] = time.perf_counter() - t
    cands = segment_parts(s, mesh, masks, perc.point_segmenter, cfg, rasterizer=rast, timings=timings)
    total = time.perf_counter() - t
    cpu1 = proc.cpu_times()
    cpu = (cpu1.user - cpu0.user) + (cpu1.system - cpu0.system)
    stop.set()
    th.join()
    q = segmentation_quality(cands, read_articulate3d(s.gt_dir), seen)
    out.put({"frames": len(s.frames), "faces": mesh.n_faces, "decimate": decimate, "total_s": total, "cpu_s": cpu, "load_avg": os.getloadavg()[0],
             **{k: v for k, v in timings.items()}, "peak_rss_gb": peak[0] / 2**30, "rss_before_gb": base / 2**30,
             "recall": q.recall(0.5), "precision": q.precision(0.5), "eligible_parts": len(q.eligible)})


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", type=Path, default=None, help="scene folder with GT (default: generate the 300-frame kitchen)")
    p.add_argument("--n-frames", type=int, default=300, help="frames of the generated scene")
    p.add_argument("--edge", type=float, default=0.012, help="furniture triangle size (m) of the generated scene")
    p.add_argument("--frames", default="75,150,300", help="frame counts to fuse")
    p.add_argument("--no-decimate-row", action="store_true", help="skip the run without decimation")
    p.add_argument("--no-decimate-frames", type=int, default=75, help="frames of the run without decimation")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)

    from rich.console import Console
    from rich.table import Table

    scene, cache = scene_and_masks(a.scene, a.n_frames, a.edge)
    runs = [(int(n), True) for n in a.frames.split(",")]
    if not a.no_decimate_row:
        runs.append((a.no_decimate_frames, False))
    ctx = mp.get_context("spawn")
    rows = []
    for n, dec in runs:
        q = ctx.Queue()
        pr = ctx.Process(target=run_one, args=(str(scene), str(cache), n, dec, q))
        pr.start()
        rows.append(q.get())
        pr.join()
        print(json.dumps(rows[-1]))
    cols = ["frames", "faces", "decimate", "total_s", "cpu_s", "load_avg", "bvh", "prepare", "lift", "fuse", "topk_reseg_clip",
            "n_proposals", "n_candidates", "peak_rss_gb", "recall", "precision"]
    t = Table(title=f"fusion on {scene.name} ({os.cpu_count()} cores)")
    for c in cols:
        t.add_column(c)
    for r in rows:
        t.add_row(*[f"{r.get(c):.2f}" if isinstance(r.get(c), float) else str(r.get(c)) for c in cols])
    Console().print(t)
    if a.json:
        write_json(a.json, {"scene": str(scene), "cores": os.cpu_count(), "rows": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
