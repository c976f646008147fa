"""Where the models backend's perception stage spends its time on a GPU: profiler tables and variants.

    python3 benchmarks/profile_models_stage.py --out DIR            # GPU: real architectures, random weights
    python3 benchmarks/profile_models_stage.py --tiny --frames 8 --out DIR   # CPU smoke run

The stage as bench_models_scene.py runs it (its run_stage: perceive() per batch in worker threads, masks
packed, GPU utilisation read through NVML), then:
  * torch.profiler over --profile-frames frames: ops by self CPU time and by self device time, and the
    device's busy time against the wall time (is the stage bound by the GPU or by the host?);
  * cProfile of the same frames (one worker): the Python functions that hold the host;
  * variants on the same --frames frames (not with --quick): 1, 2, 8 workers; batch 4 and 16; JPEG decoding on the GPU (torchvision.io.decode_jpeg) against OpenCV.
Writes DIR/profile.json (the timings) and DIR/profile_tables.txt (the profiler tables).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("HF_HUB_OFFLINE", "1")

from bench_models_scene import chat_server, run_stage, sync, write_frames  # noqa: E402

from react3d_core.atomic import write_json, write_text  # noqa: E402


def profile(perception: Any, frames: list[Any], cfg: Any, batch: int, rows: int) -> tuple[dict[str, Any], str]:
    """torch.profiler over the stage in one thread (it records only the thread that starts it): busy device
    time vs wall, and the top ops by self CPU / device time."""
    import torch
    from torch.profiler import ProfilerActivity
    from torch.profiler import profile as tprofile

    acts = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if torch.cuda.is_available() else [])
    with tprofile(activities=acts) as prof:
        row = run_stage(perception, frames, cfg, batch, 1)
    ka = prof.key_averages()
    dev_attr = "self_device_time_total" if hasattr(ka[0], "self_device_time_total") else "self_cuda_time_total"
    # device time of the kernels and copies themselves: the ops that launch them report the same time again
    # (the first recorded profiles, benchmarks/results/gpu_h100_profile_*.json, summed both: 'busy' > wall)
    busy_us = sum(getattr(e, dev_attr, 0) for e in ka if str(getattr(e, "device_type", "")).endswith(("CUDA", "PrivateUse1")))
    cpu_us = sum(e.self_cpu_time_total for e in ka)
    summary = {"profiled": row, "device_kernel_s": busy_us / 1e6, "device_kernel_fraction": busy_us / 1e6 / row["seconds"],
               "self_cpu_s_all_threads": cpu_us / 1e6}
    sort_dev = "self_cuda_time_total" if dev_attr == "self_cuda_time_total" else "self_device_time_total"
    tables = (f"# profiled: {row}\n# device kernels and copies {busy_us / 1e6:.2f} s of {row['seconds']:.2f} s wall\n\n"
              "## by self CPU time\n" + ka.table(sort_by="self_cpu_time_total", row_limit=rows, max_name_column_width=60) +
              "\n\n## by self device time\n" + ka.table(sort_by=sort_dev, row_limit=rows, max_name_column_width=60))
    try:  # which Python code holds the host: ops grouped by their calling stack are not kept (no with_stack); by shapes instead
        tables += "\n\n## by self CPU time, grouped by input shapes\n" + prof.key_averages(group_by_input_shape=True).table(
            sort_by="self_cpu_time_total", row_limit=rows, max_name_column_width=60)
    except Exception as exc:  # noqa: BLE001 - a table the profiler could not build is reported, not fatal
        tables += f"\n(shape table not available: {exc})"
    return summary, tables


def python_profile(perception: Any, frames: list[Any], cfg: Any, batch: int, rows: int) -> str:
    """cProfile of the stage in one thread: which Python functions hold the host (time blocked waiting for the
    device shows up in the calls that synchronise, e.g. ``.cpu()``)."""
    import cProfile
    import io
    import pstats

    pr = cProfile.Profile()
    pr.enable()
    run_stage(perception, frames, cfg, batch, 1)
    pr.disable()
    text = io.StringIO()
    st = pstats.Stats(pr, stream=text)
    st.sort_stats("tottime").print_stats(rows)
    st.sort_stats("cumulative").print_stats(rows)
    return text.getvalue()


def jpeg_decode(frames: list[Any]) -> dict[str, float]:
    """ms per frame: OpenCV on the host (the pipeline's reader) vs nvJPEG through torchvision, batched."""
    import torch

    from react3d_core.scene_io.images import frame_rgb

    out: dict[str, float] = {}
    t = time.perf_counter()
    for f in frames:
        frame_rgb(f)
    out["opencv_ms"] = 1000 * (time.perf_counter() - t) / len(frames)
    try:
        import torchvision.io as tio
    except ImportError:
        return out
    if not torch.cuda.is_available():
        return out
    data = [tio.read_file(str(f.rgb.path)) for f in frames]
    tio.decode_jpeg(data[:2], device="cuda")  # warm-up
    sync()
    t = time.perf_counter()
    for s in range(0, len(data), 8):
        tio.decode_jpeg(data[s : s + 8], device="cuda")
    sync()
    out["nvjpeg_b8_ms"] = 1000 * (time.perf_counter() - t) / len(frames)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tiny", action="store_true")
    p.add_argument("--frames", type=int, default=64)
    p.add_argument("--profile-frames", type=int, default=32)
    p.add_argument("--width", type=int, default=1920)
    p.add_argument("--height", type=int, default=1440)
    p.add_argument("--batch", type=int, default=8)
    p.add_argument("--workers", type=int, default=4)
    p.add_argument("--max-detections", type=int, default=16)
    p.add_argument("--rows", type=int, default=40)
    p.add_argument("--quick", action="store_true", help="only the base run and the profiles")
    p.add_argument("--out", required=True, help="a new or empty folder for profile.json and profile_tables.txt")
    a = p.parse_args(argv)

    import torch
    import transformers

    from react3d_core.config import PerceptionConfig
    from react3d_models import make_model_perception
    from react3d_models.random_checkpoints import save_random_checkpoints

    transformers.utils.logging.disable_progress_bar()
    gpu = torch.cuda.is_available()
    tiny = a.tiny or not gpu
    device = torch.device("cuda" if gpu else "cpu")
    out = Path(a.out)
    if out.exists() and any(out.iterdir()):
        p.error(f"--out {a.out}: the folder is not empty; give a new or empty one (profile.json and profile_tables.txt are written there)")
    out.mkdir(parents=True, exist_ok=True)
    res: dict[str, Any] = {"device": torch.cuda.get_device_name(0) if gpu else "cpu", "torch": torch.__version__,
                           "transformers": transformers.__version__, "tiny": tiny, "size": [a.width, a.height]}

    def save() -> None:
        write_json(out / "profile.json", res)

    with tempfile.TemporaryDirectory(prefix="react3d-profile-models-") as tmp:
        work = Path(tmp)
        paths = save_random_checkpoints(work / "models", "tiny" if tiny else "real", "vit_h", build_device=device)
        frames = write_frames(work / "frames", max(a.frames, a.profile_frames), a.width, a.height)
        srv, url = chat_server()
        cfg = PerceptionConfig(backend="models", batch_size=a.batch, models=dict(
            detector_model=str(paths["detector"]), sam_model=str(paths["sam"]), tagger_model=str(paths["clip"]),
            tag_filter_endpoint=url, box_threshold=0.3, max_detections=a.max_detections, batch_size=a.batch,
            device=str(device)))
        perception = make_model_perception(cfg)
        fr = frames[: a.frames]
        run_stage(perception, frames[: a.batch], cfg, a.batch, 1)  # warm-up
        runs: dict[str, Any] = {}
        res["runs"] = runs
        runs["base"] = run_stage(perception, fr, cfg, a.batch, a.workers)
        print("base", runs["base"], flush=True)
        save()
        summary, tables = profile(perception, frames[: a.profile_frames], cfg, a.batch, a.rows)
        res["profile"] = summary
        tables += "\n\n## Python (cProfile), one worker\n" + python_profile(perception, frames[: a.profile_frames], cfg, a.batch, a.rows)
        write_text(out / "profile_tables.txt", tables)
        print(summary, flush=True)
        save()
        if a.quick:
            srv.shutdown()
            return 0
        for w in (1, 2, 8):
            runs[f"workers{w}"] = run_stage(perception, fr, cfg, a.batch, w)
            print(f"workers{w}", runs[f"workers{w}"], flush=True)
        save()
        for b in (4, 16):
            cfg_b = cfg.model_copy(update={"batch_size": b})
            perception.segmenter.batch_size = perception.tagger.batch_size = b
            runs[f"batch{b}"] = run_stage(perception, fr, cfg_b, b, a.workers)
            print(f"batch{b}", runs[f"batch{b}"], flush=True)
        perception.segmenter.batch_size = perception.tagger.batch_size = a.batch
        runs["base_again"] = run_stage(perception, fr, cfg, a.batch, a.workers)
        print("base_again", runs["base_again"], flush=True)
        res["jpeg"] = jpeg_decode(fr[:32])
        print("jpeg", res["jpeg"], flush=True)
        save()
        srv.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
