"""The models backend over a whole scene's frames: the perception stage, ours versus reference-style calls.

    python3 benchmarks/bench_models_scene.py --json bench_models_scene.json     # GPU: 300 frames, 1920x1440
    python3 benchmarks/bench_models_scene.py --tiny --frames 6 --json x.json     # CPU smoke run, tiny models

Models: random weights of the real architectures (Grounding DINO-T, SAM ViT-H, CLIP ViT-B/32; with
--tiny a few layers), saved with save_pretrained and loaded through the backend's own loaders; nothing
is downloaded. The tag filter is an OpenAI-style chat endpoint faked on 127.0.0.1.

  * frames: --frames JPEGs of --width x --height written to a temporary folder and read back by the
    pipeline's own image reader, as from a scan;
  * ours: make_model_perception (bf16 on a GPU) and the pipeline's perceive() over batches of --batch
    frames in --workers threads (the convert flow's task runner), each batch's masks bit-packed as the
    perception task stores them: wall time, frames/s, peak GPU memory. Variants on --subset frames:
    one worker; pre-processing on the CPU; SAM with eager attention;
  * per model call: ms per frame, sequential, batch --batch: image read, CLIP, Grounding DINO, SAM
    encoder, SAM decoder with its masks;
  * reference-style: per frame, Grounding DINO and SAM loaded anew in fp32 with stock from_pretrained and
    called with batch 1 as per-frame scripts do, Grounding DINO post-processed on its output tensors as in
    its model card (--ref-frames frames), and the same calls with the models kept (forward only);
  * out-of-memory: the segmenter asked for --subset frames in one batch under a memory cap that fits
    about --batch of them; split_on_oom must halve the batch until it fits and return every frame.

A random detector passes arbitrary boxes: --max-detections (default 16, a kitchen view) caps them per
frame so that the mask work matches a real scene. Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
os.environ.setdefault("HF_HUB_OFFLINE", "1")

from react3d_core.atomic import write_json  # noqa: E402

PHRASES = ["cabinet door", "door", "drawer door"]


def chat_server() -> tuple[ThreadingHTTPServer, str]:
    """A local OpenAI-style endpoint that keeps cabinet and drawer (the tag filter's LLM)."""
    reply = json.dumps({"choices": [{"message": {"content": '["cabinet", "drawer"]'}}]}).encode()

    class H(BaseHTTPRequestHandler):
        def do_POST(self) -> None:  # noqa: N802 - http.server API
            self.rfile.read(int(self.headers["Content-Length"]))
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(reply)))
            self.end_headers()
            self.wfile.write(reply)

        def log_message(self, *args: Any) -> None:
            pass

    srv = ThreadingHTTPServer(("127.0.0.1", 0), H)
    srv.daemon_threads = True
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    return srv, f"http://127.0.0.1:{srv.server_address[1]}/v1"


def write_frames(folder: Path, n: int, width: int, height: int) -> list[Any]:
    """``n`` JPEG frames of a cabinet-like pattern (fronts, gaps, handles, sensor noise) and their Frames."""
    import cv2
    import numpy as np

    from react3d_core.data.frames import Frame, ImageRef, Intrinsics

    folder.mkdir(parents=True, exist_ok=True)

    def one(i: int) -> Any:
        rng = np.random.default_rng(i)
        img = np.full((height, width, 3), 200, np.uint8)
        cols = rng.integers(3, 7)
        for c in range(cols):
            x0, x1 = int(c * width / cols) + 4, int((c + 1) * width / cols) - 4
            img[height // 5 : height - height // 8, x0:x1] = rng.integers(60, 230, 3)
            hx = x1 - 30 if c % 2 else x0 + 20
            img[height // 2 - 60 : height // 2 + 60, hx : hx + 8] = 30
        img = (img.astype(np.int16) + rng.normal(0, 6, img.shape)).clip(0, 255).astype(np.uint8)
        path = folder / f"frame_{i:05d}.jpg"
        cv2.imwrite(str(path), img[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, 92])
        return Frame(frame_id=f"frame_{i:05d}", rgb=ImageRef(path=path, kind="jpg"),
                     intrinsics=Intrinsics(fx=0.8 * width, fy=0.8 * width, cx=width / 2, cy=height / 2, width=width, height=height),
                     pose=np.eye(4))

    with ThreadPoolExecutor(max(1, min(16, os.cpu_count() or 1))) as ex:
        return list(ex.map(one, range(n)))


def sync() -> None:
    import torch

    if torch.cuda.is_available():
        torch.cuda.synchronize()


def timed(fn: Callable[[], Any]) -> tuple[float, Any]:
    sync()
    t = time.perf_counter()
    out = fn()
    sync()
    return time.perf_counter() - t, out


class GpuUtilisation:
    """The device's own utilisation counter (percent of time a kernel ran, through NVML) sampled every
    50 ms in a thread while the block runs; ``mean`` is None without a GPU or NVML."""

    def __enter__(self) -> GpuUtilisation:
        import torch

        self.samples: list[float] = []
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        if torch.cuda.is_available():
            self._thread.start()
        return self

    def _sample(self) -> None:
        import torch

        while not self._done.wait(0.05):
            try:
                self.samples.append(float(torch.cuda.utilization()))
            except Exception:  # noqa: BLE001 - no NVML here: no utilisation figure
                return

    def __exit__(self, *exc: object) -> None:
        self._done.set()

    @property
    def mean(self) -> float | None:
        return sum(self.samples) / len(self.samples) if self.samples else None


def run_stage(perception: Any, frames: list[Any], cfg: Any, batch: int, workers: int) -> dict[str, Any]:
    """The perception stage as the flow runs it: perceive() per batch in ``workers`` threads, masks packed
    (one worker: in this thread, so a profiler started here records it)."""
    import torch

    from react3d_core.pipeline import perceive
    from react3d_core.pipeline.steps import pack_masks

    batches = [frames[s : s + batch] for s in range(0, len(frames), batch)]
    if torch.cuda.is_available():
        torch.cuda.reset_peak_memory_stats()

    def one(b: list[Any]) -> int:
        r = perceive(perception, b, cfg)
        pack_masks([r["masks"]])  # what the perception task stores
        return sum(len(m) for m in r["masks"].values())

    with GpuUtilisation() as util:
        t, res = timed(lambda: list(ThreadPoolExecutor(workers).map(one, batches)) if workers > 1 else [one(b) for b in batches])
    row = {"frames": len(frames), "batch": batch, "workers": workers, "seconds": t, "frames_per_s": len(frames) / t,
           "masks": sum(res)}
    if torch.cuda.is_available():
        row["peak_gpu_gib"] = torch.cuda.max_memory_allocated() / 2**30
    if util.mean is not None:
        row["gpu_util_mean_pct"] = util.mean
    return row


def per_call(perception: Any, frames: list[Any], batch: int, reps: int) -> dict[str, float]:
    """ms per frame of each model call, sequential, on ``reps`` batches of ``batch`` frames."""
    from react3d_core.scene_io.images import frame_rgb
    from react3d_models.grounded_sam import QUERIES_PER_DETECTION, detect, sam_box_masks_batched, sam_image_embeddings, top_detections

    seg = perception.segmenter
    acc = {"read_jpeg": 0.0, "clip_tagger": 0.0, "grounding_dino": 0.0, "sam_encoder": 0.0, "sam_decoder_masks": 0.0}
    n = 0
    for r in range(reps):
        fr = frames[r * batch : (r + 1) * batch]
        if not fr:
            break
        t, images = timed(lambda: [frame_rgb(f) for f in fr])
        acc["read_jpeg"] += t
        acc["clip_tagger"] += timed(lambda: perception.tagger.probabilities(images))[0]
        t, dets = timed(lambda: detect(seg.detector, images, PHRASES, seg.box_threshold, seg.text_threshold, seg.gpu_preprocess,
                                       QUERIES_PER_DETECTION * seg.max_detections))
        acc["grounding_dino"] += t
        dets = [top_detections(d, seg.nms_iou, seg.max_detections) for d in dets]
        keep = [i for i, d in enumerate(dets) if len(d.boxes)]
        t, (emb, inputs) = timed(lambda: sam_image_embeddings(seg.sam, [images[i] for i in keep] or images[:1], seg.gpu_preprocess))
        acc["sam_encoder"] += t
        with_boxes = [d.boxes for d in dets if len(d.boxes)]
        acc["sam_decoder_masks"] += timed(lambda: sam_box_masks_batched(seg.sam, emb, inputs, with_boxes) if with_boxes else [])[0]
        n += len(fr)
    out = {k: 1000 * v / max(n, 1) for k, v in acc.items()}
    out["models_total"] = sum(v for k, v in out.items() if k != "read_jpeg")
    return out


def stock_models(paths: dict[str, Path], device: Any) -> tuple[Any, Any]:
    """Grounding DINO and SAM as a per-frame script loads them: fp32, stock ``from_pretrained``, none of
    the backend's changes (no cached SAM position tables)."""
    import torch
    from transformers import AutoProcessor, GroundingDinoForObjectDetection, SamModel, SamProcessor

    from react3d_models.runtime import Loaded

    det = GroundingDinoForObjectDetection.from_pretrained(str(paths["detector"])).to(device).eval()
    sam = SamModel.from_pretrained(str(paths["sam"])).to(device).eval()
    return (Loaded(det, AutoProcessor.from_pretrained(str(paths["detector"])), device, torch.float32),
            Loaded(sam, SamProcessor.from_pretrained(str(paths["sam"])), device, torch.float32))


def stock_detect(det: Any, image: Any, box_t: float, text_t: float) -> Any:
    """One frame through Grounding DINO as its model card does: processor, forward, post-processing on the
    model's output tensors (on the GPU when the model is there)."""
    import torch

    from react3d_models.grounded_sam import detections_from_outputs, detector_prompt

    inputs = det.processor(images=[image], text=[detector_prompt(PHRASES)], return_tensors="pt").to(det.device)
    with torch.inference_mode():
        out = det.model(**inputs)
    return detections_from_outputs(det.processor, out, inputs["input_ids"], [image.shape[:2]], PHRASES, box_t, text_t)[0]


def reference(paths: dict[str, Path], frames: list[Any], n: int, device: Any, box_t: float, text_t: float,
              max_det: int, rebuild: bool) -> float:
    """Seconds per frame of the reference-style call: stock models in fp32, batch 1, (re)loaded per frame
    when ``rebuild``; transformers' input checks on, as they are by default."""
    import torch

    from react3d_core.scene_io.images import frame_rgb
    from react3d_models.grounded_sam import sam_box_masks, sam_image_embeddings, top_detections

    saved = os.environ.get("TRANSFORMERS_DISABLE_TORCH_CHECK")
    os.environ["TRANSFORMERS_DISABLE_TORCH_CHECK"] = "0"
    models = None if rebuild else stock_models(paths, device)

    def one(f: Any) -> None:
        det, sam = models or stock_models(paths, device)
        image = frame_rgb(f)
        d = top_detections(stock_detect(det, image, box_t, text_t), 0.8, max_det)
        emb, inputs = sam_image_embeddings(sam, [image], on_device=False)
        if len(d.boxes):
            sam_box_masks(sam, emb, inputs, 0, d.boxes)

    try:
        one(frames[0])  # warm-up (CUDA context, kernels)
        total = sum(timed(lambda f=f: one(f))[0] for f in frames[1 : n + 1])
    finally:
        if saved is None:
            os.environ.pop("TRANSFORMERS_DISABLE_TORCH_CHECK", None)
        else:
            os.environ["TRANSFORMERS_DISABLE_TORCH_CHECK"] = saved
    del models
    if torch.cuda.is_available():
        torch.cuda.empty_cache()
    return total / max(1, min(n, len(frames) - 1))


def oom_split(perception: Any, frames: list[Any], cap_gib: float) -> dict[str, Any]:
    """The segmenter on all ``frames`` at once under a memory cap: split_on_oom halves until batches fit."""
    import torch

    from react3d_core.pipeline.steps import split_on_oom
    from react3d_core.scene_io.images import frame_rgb

    seg = perception.segmenter
    images = [frame_rgb(f) for f in frames]
    sizes: list[tuple[int, bool]] = []
    old = seg.batch_size
    seg.batch_size = len(frames)

    def fn(fr: list[Any], im: list[Any]) -> list[Any]:
        try:
            out = seg.segment(fr, im, PHRASES)
        except Exception as exc:
            sizes.append((len(fr), False))
            raise exc
        sizes.append((len(fr), True))
        return out

    total = torch.cuda.get_device_properties(0).total_memory
    torch.cuda.empty_cache()
    torch.cuda.set_per_process_memory_fraction(min(1.0, cap_gib * 2**30 / total))
    try:
        t, res = timed(lambda: split_on_oom(fn, frames, images))
    finally:
        torch.cuda.set_per_process_memory_fraction(1.0)
        seg.batch_size = old
    return {"frames": len(frames), "cap_gib": cap_gib, "seconds": t, "returned_frames": len(res),
            "attempts": [s for s, _ in sizes], "failed_attempts": sum(not ok for _, ok in sizes),
            "largest_batch_that_fit": max((s for s, ok in sizes if ok), default=0)}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tiny", action="store_true", help="few-layer models (automatic without a GPU)")
    p.add_argument("--frames", type=int, default=300)
    p.add_argument("--width", type=int, default=1920)
    p.add_argument("--height", type=int, default=1440)
    p.add_argument("--batch", type=int, default=8, help="frames per perceive() call and per model forward (perception.batch_size, perception.models.batch_size)")
    p.add_argument("--workers", type=int, default=4, help="threads running perceive() (the flow runs 4)")
    p.add_argument("--subset", type=int, default=64, help="frames for the variants and the out-of-memory check")
    p.add_argument("--ref-frames", type=int, default=3)
    p.add_argument("--max-detections", type=int, default=16)
    p.add_argument("--box-threshold", type=float, default=0.3)
    p.add_argument("--sam", default="vit_h", choices=["vit_h", "vit_b"])
    p.add_argument("--quick", action="store_true", help="only the whole-scene run, one per-call batch and the reference")
    p.add_argument("--work", default=None, help="a new or empty folder for checkpoints and frames (default: a temporary one)")
    p.add_argument("--plain-mask-copy", action="store_true",
                   help="the 'before' of the mask bit-packing: SAM masks cross to the host one byte per pixel (plain .cpu())")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)

    import torch
    from rich.console import Console

    from react3d_core.config import PerceptionConfig
    from react3d_models import make_model_perception
    from react3d_models.random_checkpoints import save_random_checkpoints
    from react3d_models.runtime import clear_cache

    if a.plain_mask_copy:
        from react3d_models import grounded_sam

        grounded_sam.masks_to_host = lambda m: m.cpu().numpy()  # type: ignore[assignment]
    gpu = torch.cuda.is_available()
    tiny = a.tiny or not gpu
    device = torch.device("cuda" if gpu else "cpu")
    if not gpu:
        torch.set_num_threads(max(1, min(4, os.cpu_count() or 1)))
    if a.work is not None and Path(a.work).exists() and any(Path(a.work).iterdir()):
        p.error(f"--work {a.work}: the folder is not empty; give a new or empty one (checkpoints and frames are written there)")
    work_ctx = tempfile.TemporaryDirectory(prefix="react3d-bench-models-") if a.work is None else None
    work = Path(a.work or work_ctx.name)  # type: ignore[union-attr]
    result: dict[str, Any] = {"device": torch.cuda.get_device_name(0) if gpu else "cpu", "torch": torch.__version__,
                              "tiny": tiny, "frames": a.frames, "size": [a.width, a.height], "sam": a.sam,
                              "max_detections": a.max_detections, "mask_copy": "plain" if a.plain_mask_copy else "packed"}

    def save() -> None:  # after every section: a run cut short still leaves what it measured
        if a.json:
            write_json(a.json, result)

    import transformers

    transformers.utils.logging.disable_progress_bar()
    result["transformers"] = transformers.__version__
    con = Console(width=150)
    t0 = time.perf_counter()
    paths = save_random_checkpoints(work / "models", "tiny" if tiny else "real", a.sam, build_device=device)
    result["build_checkpoints_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    frames = write_frames(work / "frames", a.frames, a.width, a.height)
    result["write_frames_s"] = time.perf_counter() - t0
    srv, url = chat_server()
    cfg = PerceptionConfig(backend="models", batch_size=a.batch, models=dict(
        detector_model=str(paths["detector"]), sam_model=str(paths["sam"]), tagger_model=str(paths["clip"]),
        tag_filter_endpoint=url, box_threshold=a.box_threshold, max_detections=a.max_detections, batch_size=a.batch,
        device=str(device)))

    t, perception = timed(lambda: make_model_perception(cfg))
    result["load_models_s"] = t
    save()
    con.print(f"[bold]models loaded in {t:.1f} s; {a.frames} frames {a.width}x{a.height}")
    sub = frames[: max(2, min(a.subset, len(frames)))]
    run_stage(perception, frames[: a.batch], cfg, a.batch, 1)  # warm-up
    runs = {"ours": run_stage(perception, frames, cfg, a.batch, a.workers)}
    con.print(f"ours: {runs['ours']['seconds']:.1f} s for {a.frames} frames")
    result["runs"] = runs
    save()
    if a.quick:
        result["per_call_ms_per_frame"] = {f"batch{a.batch}": per_call(perception, frames, a.batch, 1)}
    else:
        variants(result, runs, perception, frames, sub, cfg, a, paths, device, gpu, save)
    result["ref_fp32_b1_forward_s_per_frame"] = reference(paths, frames, 2 * a.ref_frames, device, a.box_threshold,
                                                          cfg.models.text_threshold, a.max_detections, rebuild=False)
    result["ref_fp32_b1_rebuild_s_per_frame"] = reference(paths, frames, a.ref_frames, device, a.box_threshold,
                                                          cfg.models.text_threshold, a.max_detections, rebuild=True)
    ours_pf = runs["ours"]["seconds"] / runs["ours"]["frames"]
    result["speedup_vs_ref_forward"] = result["ref_fp32_b1_forward_s_per_frame"] / ours_pf
    result["speedup_vs_ref_rebuild"] = result["ref_fp32_b1_rebuild_s_per_frame"] / ours_pf
    srv.shutdown()
    clear_cache()
    report(result, runs, tiny, con)
    save()
    if work_ctx is not None:
        work_ctx.cleanup()
    return 0


def variants(result: dict[str, Any], runs: dict[str, Any], perception: Any, frames: list[Any], sub: list[Any], cfg: Any,
             a: argparse.Namespace, paths: dict[str, Path], device: Any, gpu: bool, save: Callable[[], None]) -> None:
    """Subset runs (one worker, CPU pre-processing), per-call timings, eager attention, the out-of-memory split."""
    import torch

    runs["ours_subset"] = run_stage(perception, sub, cfg, a.batch, a.workers)
    runs["one_worker_subset"] = run_stage(perception, sub, cfg, a.batch, 1)
    for part in (perception.segmenter, perception.tagger):
        part.gpu_preprocess = False
    runs["cpu_preprocess_subset"] = run_stage(perception, sub, cfg, a.batch, a.workers)
    for part in (perception.segmenter, perception.tagger):
        part.gpu_preprocess = True
    result["runs"] = runs
    save()
    result["per_call_ms_per_frame"] = {f"batch{b}": per_call(perception, frames, b, max(1, 24 // b)) for b in (1, a.batch)}
    if gpu:
        result["per_call_ms_per_frame"][f"batch{2 * a.batch}"] = per_call(perception, frames, 2 * a.batch, 2)
        # eager attention in SAM's encoder, the rest unchanged (SDPA is transformers' default)
        from transformers import SamModel

        saved = perception.segmenter.sam
        eager = SamModel.from_pretrained(str(paths["sam"]), dtype=saved.dtype, attn_implementation="eager").to(device).eval()
        perception.segmenter.sam = dataclasses.replace(saved, model=eager)
        result["sam_eager_attention_ms_per_frame"] = per_call(perception, frames, a.batch, 2)["sam_encoder"]
        perception.segmenter.sam = saved
        del eager
        torch.cuda.empty_cache()
        weights = torch.cuda.memory_allocated() / 2**30
        act = max(1.0, runs["one_worker_subset"]["peak_gpu_gib"] - weights)
        result["oom_split"] = oom_split(perception, sub[: 4 * a.batch], weights + 1.5 * act)
        save()


def report(result: dict[str, Any], runs: dict[str, Any], tiny: bool, con: Any) -> None:
    """The tables and headline numbers on the console."""
    from rich.table import Table

    table = Table(title=f"models backend, perception stage on {result['device']}{' (tiny models)' if tiny else ''}")
    for c in ("run", "frames", "batch", "workers", "s", "frames/s", "peak GiB"):
        table.add_column(c)
    for name, r in runs.items():
        table.add_row(name, str(r["frames"]), str(r["batch"]), str(r["workers"]), f"{r['seconds']:.2f}",
                      f"{r['frames_per_s']:.2f}", f"{r.get('peak_gpu_gib', 0):.1f}")
    table.add_row("ref fp32 b1 (forward)", "", "1", "1", f"{result['ref_fp32_b1_forward_s_per_frame']:.3f}/frame",
                  f"{1 / result['ref_fp32_b1_forward_s_per_frame']:.2f}", "")
    table.add_row("ref fp32 b1 (rebuilt)", "", "1", "1", f"{result['ref_fp32_b1_rebuild_s_per_frame']:.3f}/frame",
                  f"{1 / result['ref_fp32_b1_rebuild_s_per_frame']:.2f}", "")
    con.print(table)
    calls = Table(title="ms per frame per model call (sequential)")
    calls.add_column("batch")
    keys = list(next(iter(result["per_call_ms_per_frame"].values())))
    for k in keys:
        calls.add_column(k)
    for b, row in result["per_call_ms_per_frame"].items():
        calls.add_row(b, *[f"{row[k]:.1f}" for k in keys])
    con.print(calls)
    con.print(f"speed-up vs reference forward-only: {result['speedup_vs_ref_forward']:.1f}x; "
              f"vs rebuilt per call: {result['speedup_vs_ref_rebuild']:.1f}x")
    if "oom_split" in result:
        con.print(f"out-of-memory split: {result['oom_split']}")


if __name__ == "__main__":
    raise SystemExit(main())
