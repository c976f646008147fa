"""Perception-model throughput: reference-style calls versus the react3d_models way of calling them.

    python3 benchmarks/bench_models.py --json bench_models.json            # GPU: real architectures
    python3 benchmarks/bench_models.py --tiny --json bench_models.json     # CPU smoke run, tiny configs
    python3 benchmarks/bench_models.py --mask-transfer --models "" --json mask_transfer.json   # GPU: masks to host only

Models are built from configs with random weights (nothing is downloaded): SAM ViT-H and ViT-B image
encoders at 1024x1024, Grounding DINO-T (Swin-T + BERT-base, transformers' default config) at
800x1066 with a 16-token prompt. For each model:
  * reference: fp32, batch 1, the model built anew for every call (as per-frame scripts do);
    reported both as forward-only img/s and img/s including the rebuild;
  * ours: built once, bf16 on GPU (fp32 on CPU), batches of --batch frames, torch.inference_mode.
``--mask-transfer`` (CUDA only) also times 16 bool masks of 1920x1440 from the GPU to numpy: a plain
``.cpu().numpy()`` against host_sync.masks_to_host (bits packed on the GPU, unpacked on the host).
Prints a table and writes JSON. Without a GPU the real sizes take minutes per call, so ``--tiny``
(automatic on CPU unless --full) uses few-layer configs: the numbers then only show the code runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from react3d_core.atomic import write_json  # noqa: E402


def sam_spec(variant: str, tiny: bool) -> tuple[Callable[[], Any], Callable[[Any, int, Any, Any], Any]]:
    """(build, run) for a SAM image encoder; run(model, batch, device, dtype) does one forward."""
    import torch
    from transformers import SamModel

    from react3d_models.random_checkpoints import sam_config

    cfg = sam_config("tiny" if tiny else "real", variant)
    size = cfg.vision_config.image_size

    def build() -> Any:
        return SamModel(cfg).eval()

    def run(model: Any, batch: int, device: Any, dtype: Any) -> Any:
        x = torch.randn(batch, 3, size, size, device=device, dtype=dtype)
        return model.get_image_embeddings(x)

    return build, run


def gdino_spec(tiny: bool) -> tuple[Callable[[], Any], Callable[[Any, int, Any, Any], Any]]:
    """(build, run) for Grounding DINO-T at 800x1066 with a 16-token prompt (tiny: 64x96)."""
    import torch
    from transformers import GroundingDinoForObjectDetection

    from react3d_models.random_checkpoints import detector_config

    cfg = detector_config("tiny" if tiny else "real")
    hw = (64, 96) if tiny else (800, 1066)

    def build() -> Any:
        return GroundingDinoForObjectDetection(cfg).eval()

    def run(model: Any, batch: int, device: Any, dtype: Any) -> Any:
        g = torch.Generator().manual_seed(0)
        ids = torch.randint(1000 if not tiny else 5, cfg.text_config.vocab_size, (batch, 16), generator=g).to(device)
        x = torch.randn(batch, 3, *hw, device=device, dtype=dtype)
        return model(pixel_values=x, input_ids=ids, attention_mask=torch.ones_like(ids))

    return build, run


def timed(fn: Callable[[], Any], device: Any) -> float:
    import torch

    if device.type == "cuda":
        torch.cuda.synchronize(device)
    t = time.perf_counter()
    fn()
    if device.type == "cuda":
        torch.cuda.synchronize(device)
    return time.perf_counter() - t


def bench_one(name: str, build: Callable[[], Any], run: Callable[..., Any], device: Any, dtype: Any,
              batch: int, n_images: int, rebuild_calls: int) -> dict[str, Any]:
    """Reference (fp32, batch 1, rebuilt per call) versus ours (built once, dtype, batched)."""
    import torch

    def build_on() -> Any:  # random initialisation on the device itself (ViT-H on a CPU takes tens of seconds)
        with device:
            return build()

    with torch.inference_mode():
        # reference forward-only: fp32, batch 1 (model built once here so only the forward is timed)
        ref = build_on().to(device)
        run(ref, 1, device, torch.float32)  # warm-up
        t_fwd = sum(timed(lambda: run(ref, 1, device, torch.float32), device) for _ in range(n_images))
        del ref
        # reference with rebuild per call
        t_rb = sum(timed(lambda: run(build_on().to(device), 1, device, torch.float32), device) for _ in range(rebuild_calls))
        ours = build_on().to(device=device, dtype=dtype)
        if device.type == "cuda":
            torch.cuda.reset_peak_memory_stats(device)
        run(ours, batch, device, dtype)  # warm-up
        n_batches = max(1, n_images // batch)
        t_ours = sum(timed(lambda: run(ours, batch, device, dtype), device) for _ in range(n_batches))
        del ours
    peak_gb = None
    if device.type == "cuda":
        peak_gb = torch.cuda.max_memory_allocated(device) / 2**30
        torch.cuda.empty_cache()
    row = {"model": name, "ref_fp32_b1_img_s": n_images / t_fwd, "ref_rebuild_img_s": rebuild_calls / t_rb,
           "ours_img_s": n_batches * batch / t_ours, "batch": batch, "dtype": str(dtype).replace("torch.", ""), "ours_peak_gpu_gb": peak_gb}
    row["speedup_vs_ref"] = row["ours_img_s"] / row["ref_fp32_b1_img_s"]
    return row


def mask_transfer(device: Any, n: int = 16, hw: tuple[int, int] = (1440, 1920), repeats: int = 20) -> dict[str, Any] | None:
    """Median ms of bool masks (n,H,W) on the GPU -> numpy: plain ``.cpu().numpy()`` vs ``masks_to_host``."""
    import statistics

    import numpy as np
    import torch

    from react3d_models.host_sync import masks_to_host

    if device.type != "cuda":
        print("--mask-transfer needs a CUDA device: skipped")
        return None
    g = torch.Generator(device).manual_seed(0)
    m = torch.rand((n, *hw), device=device, generator=g) < 0.3
    ways = {"plain_cpu_numpy": lambda: m.cpu().numpy(), "masks_to_host": lambda: masks_to_host(m)}
    assert np.array_equal(ways["plain_cpu_numpy"](), ways["masks_to_host"]())
    row: dict[str, Any] = {"masks": n, "height": hw[0], "width": hw[1], "repeats": repeats, "bool_mb": m.numel() / 1e6}
    for name, fn in ways.items():
        for _ in range(3):  # warm-up (pinned host blocks, kernels)
            fn()
        row[f"{name}_ms"] = 1000 * statistics.median(timed(fn, device) for _ in range(repeats))
    row["speedup"] = row["plain_cpu_numpy_ms"] / row["masks_to_host_ms"]
    print(f"masks to host, {n} x {hw[0]}x{hw[1]} bool ({row['bool_mb']:.0f} MB), median of {repeats}: "
          f"plain .cpu().numpy() {row['plain_cpu_numpy_ms']:.2f} ms, masks_to_host {row['masks_to_host_ms']:.2f} ms "
          f"({row['speedup']:.1f}x)")
    return row


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tiny", action="store_true", help="few-layer configs (automatic without a GPU unless --full)")
    p.add_argument("--full", action="store_true", help="real sizes even on CPU (slow)")
    p.add_argument("--batch", type=int, default=8)
    p.add_argument("--images", type=int, default=16, help="images per measurement")
    p.add_argument("--rebuild-calls", type=int, default=2)
    p.add_argument("--models", default="sam_vit_h,sam_vit_b,gdino_t", help='comma-separated; "" for none')
    p.add_argument("--mask-transfer", action="store_true", help="also time 16 1920x1440 masks GPU -> numpy (CUDA only)")
    p.add_argument("--dtype", default="auto", help="ours: auto (bf16 on GPU, fp32 on CPU), bf16, fp16, fp32")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)

    import torch
    from rich.console import Console
    from rich.table import Table

    from react3d_models.runtime import resolve_dtype

    torch.manual_seed(0)
    device = torch.device("cuda" if torch.cuda.is_available() else "cpu")
    tiny = a.tiny or (device.type == "cpu" and not a.full)
    dtype = resolve_dtype(a.dtype, device)
    specs = {"sam_vit_h": lambda: sam_spec("vit_h", tiny), "sam_vit_b": lambda: sam_spec("vit_b", tiny),
             "gdino_t": lambda: gdino_spec(tiny)}
    rows = []
    for name in filter(None, (x.strip() for x in a.models.split(","))):
        build, run = specs[name.strip()]()
        rows.append(bench_one(name.strip(), build, run, device, dtype, a.batch, a.images, a.rebuild_calls))
    dev_name = torch.cuda.get_device_name(device) if device.type == "cuda" else "cpu"
    table = Table(title=f"perception models on {dev_name}{' (tiny configs)' if tiny else ''}")
    for c in ("model", "ref fp32 b1 img/s", "ref +rebuild img/s", f"ours {rows[0]['dtype'] if rows else ''} b{a.batch} img/s", "speedup"):
        table.add_column(c)
    for r in rows:
        table.add_row(r["model"], f"{r['ref_fp32_b1_img_s']:.2f}", f"{r['ref_rebuild_img_s']:.2f}", f"{r['ours_img_s']:.2f}",
                      f"{r['speedup_vs_ref']:.1f}x")
    if rows:
        Console().print(table)
    result: dict[str, Any] = {"device": dev_name, "tiny": tiny, "torch": torch.__version__, "rows": rows}
    if a.mask_transfer:
        result["mask_transfer"] = mask_transfer(device)
    if a.json:
        write_json(a.json, result)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
