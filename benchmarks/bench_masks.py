"""2D quality of the heuristic backend against GT part-id images, per frame (no fusion needed).

Usage: ``python3 benchmarks/bench_masks.py --seeds 0-9 [--frames 40] [--every 4] [--json F]``
(seeds 0-9 tune, 100+ are held apart). A GT openable part is its part-id pixels plus its handle's; it
counts when >= ``--min-px`` pixels are visible. Predicted masks are matched one-to-one by IoU >= 0.5
(Hungarian on IoU); precision/recall/F1 are summed over frames; joint-type accuracy is over matches.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from react3d_core.config import PerceptionConfig  # noqa: E402
from react3d_core.perception.heuristic import make_heuristic  # noqa: E402
from react3d_core.scene_io import load_scene  # noqa: E402
from react3d_core.scene_io.images import frame_rgb, read_label_image  # noqa: E402
from react3d_core.synthetic import generate_scene  # noqa: E402


def gt_openable_masks(part_ids: np.ndarray, meta: dict) -> dict[int, tuple[np.ndarray, str]]:
    """{part_id: (mask incl. handle, joint type)} for the openable GT parts of one frame."""
    out = {}
    for p in meta["parts"]:
        if p.get("type") not in ("revolute", "prismatic"):
            continue
        m = part_ids == p["part_id"] + 1
        if p.get("handle_part_id") is not None:
            m |= part_ids == p["handle_part_id"] + 1
        out[p["part_id"]] = (m, p["type"])
    return out


def match(pred: list[np.ndarray], gt: list[np.ndarray], thr: float = 0.5) -> list[tuple[int, int, float]]:
    """One-to-one (pred, gt, iou) pairs with IoU >= thr, maximizing total IoU."""
    if not pred or not gt:
        return []
    P = np.stack([p.ravel() for p in pred]).astype(np.float32)
    G = np.stack([g.ravel() for g in gt]).astype(np.float32)
    inter = P @ G.T
    union = P.sum(1)[:, None] + G.sum(1)[None] - inter
    iou = inter / np.maximum(union, 1)
    r, c = linear_sum_assignment(-iou)
    return [(int(i), int(j), float(iou[i, j])) for i, j in zip(r, c) if iou[i, j] >= thr]


def scene_stats(scene_dir: Path, every: int, min_px: int) -> dict:
    scene = load_scene(scene_dir)
    meta = json.loads((scene_dir / "synth_meta.json").read_text())
    t0 = time.perf_counter()
    p = make_heuristic(scene, PerceptionConfig())
    t_build = time.perf_counter() - t0
    frames = scene.frames[::every]
    tp = fp = fn = type_ok = 0
    ious: list[float] = []
    t0 = time.perf_counter()
    for f in frames:
        img = frame_rgb(f)
        masks = p.segmenter.segment([f], [img], ["cabinet door"])[0]
        preds = p.articulation.predict([f], [img])[0]
        gt = gt_openable_masks(read_label_image(f.part_ids).astype(np.int64), meta)
        keys = [k for k, (m, _) in gt.items() if m.sum() >= min_px]
        small = [gt[k][0] for k in gt if k not in keys and gt[k][0].any()]
        pm = [m.mask for m in masks]
        pairs = match(pm, [gt[k][0] for k in keys])
        matched_p = {i for i, _, _ in pairs}
        # a prediction of a barely visible GT part is neither a hit nor a false positive
        extra = [i for i in range(len(pm)) if i not in matched_p]
        ignored = {extra[i] for i, _, _ in match([pm[i] for i in extra], small)}
        tp += len(pairs)
        fp += len(pm) - len(pairs) - len(ignored)
        fn += len(keys) - len(pairs)
        ious += [iou for _, _, iou in pairs]
        for i, j, _ in pairs:  # the prediction whose mask is this detection (same front render)
            jt = next((a.joint_type for a in preds if np.array_equal(a.mask, pm[i])), None)
            type_ok += jt == gt[keys[j]][1]
    t_frames = time.perf_counter() - t0
    prec, rec = tp / max(tp + fp, 1), tp / max(tp + fn, 1)
    return {"scene": scene_dir.name, "kind": meta.get("kind") or meta.get("source"), "tp": tp, "fp": fp, "fn": fn,
            "precision": prec, "recall": rec, "f1": 2 * prec * rec / max(prec + rec, 1e-9),
            "mean_iou": float(np.mean(ious)) if ious else 0.0, "type_acc": type_ok / max(tp, 1),
            "n_fronts": len(p.segmenter.model.fronts), "build_s": t_build, "per_frame_s": t_frames / max(len(frames), 1)}


def parse_seeds(s: str) -> list[int]:
    out: list[int] = []
    for part in s.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--source", default="procedural")
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--every", type=int, default=4)
    ap.add_argument("--min-px", type=int, default=1500)
    ap.add_argument("--work", default="/tmp/heur/scenes")
    ap.add_argument("--json", dest="json_path")
    a = ap.parse_args()
    rows = []
    for seed in parse_seeds(a.seeds):
        d = Path(a.work) / f"{a.source}_{seed}_f{a.frames}"
        if not (d / "synth_meta.json").is_file():
            generate_scene(d, source=a.source, seed=seed, n_frames=a.frames)
        r = scene_stats(d, a.every, a.min_px)
        rows.append(r)
        print(f"{r['scene']:<32} {r['kind']:<10} P {r['precision']:.2f} R {r['recall']:.2f} F1 {r['f1']:.2f} "
              f"IoU {r['mean_iou']:.2f} type {r['type_acc']:.2f} fronts {r['n_fronts']:3d} "
              f"build {r['build_s']:.1f}s frame {r['per_frame_s']:.2f}s", flush=True)
    tp, fp, fn = (sum(r[k] for r in rows) for k in ("tp", "fp", "fn"))
    P, R = tp / max(tp + fp, 1), tp / max(tp + fn, 1)
    print(f"ALL  P {P:.3f} R {R:.3f} F1 {2 * P * R / max(P + R, 1e-9):.3f} "
          f"IoU {np.mean([r['mean_iou'] for r in rows]):.3f} type {np.mean([r['type_acc'] for r in rows]):.3f}")
    if a.json_path:
        Path(a.json_path).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
