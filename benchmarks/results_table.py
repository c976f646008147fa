"""Markdown results table from `react3d bench --json` files (the README's numbers).

    python3 benchmarks/results_table.py oracle:on=o.json oracle:off=onr.json heuristic:on=h.json heuristic:off=hnr.json

Each argument is LABEL=PATH; LABEL is 'backend:refinement'. Prints the paper-style table at IoU 0.5
(and 0.25), per-kind F1/joint accuracy, and the median per-stage seconds.
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict
from pathlib import Path
from statistics import median


def _f(x: float | None, pct: bool = True, d: int = 1) -> str:
    if x is None:
        return "–"
    return f"{100 * x:.{d}f}" if pct else f"{x:.{d}f}"


def main(args: list[str]) -> int:
    runs = []
    for a in args:
        label, path = a.split("=", 1)
        runs.append((label, json.loads(Path(path).read_text())))
    out = ["| perception : refinement | scenes | τ | P | R | F1 | joint acc | OE (°) | MD (m) | PDet | +M | +MO | +MOD |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in runs:
        for tau in ("0.5", "0.25"):
            a = r["aggregate"][tau]
            out.append(f"| {label} | {len(r['scenes'])} | {tau} | {_f(a['precision'])} | {_f(a['recall'])} | {_f(a['f1'])} | "
                       f"{_f(a['joint_acc'])} | {_f(a['oe'], False, 2)} | {_f(a['md'], False, 3)} | {_f(a['pdet'])} | "
                       f"{_f(a['m'])} | {_f(a['mo'])} | {_f(a['mod'])} |")
    out += ["", "Per scene type (IoU 0.5): F1 / joint accuracy", "",
            "| perception : refinement | " + " | ".join(k for k in _kinds(runs)) + " |",
            "|---|" + "---|" * len(_kinds(runs))]
    for label, r in runs:
        cells = []
        for k in _kinds(runs):
            ss = [s for s in r["scenes"] if _kind(s["scene"]) == k]
            f1 = [s["0.5"]["f1"] for s in ss if s["0.5"]["f1"] is not None]
            ja = [s["0.5"]["joint_acc"] for s in ss if s["0.5"]["joint_acc"] is not None]
            cells.append(f"{_f(sum(f1) / len(f1)) if f1 else '–'} / {_f(sum(ja) / len(ja)) if ja else '–'}")
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    out += ["", "Median seconds per scene and stage (2 cores, CPU):", "",
            "| perception : refinement | wall | peak RSS (MB) | " + " | ".join(_stages(runs)) + " |",
            "|---|---|---|" + "---|" * len(_stages(runs))]
    for label, r in runs:
        st = defaultdict(list)
        for s in r["scenes"]:
            for k, v in s["stages"].items():
                st[k].append(v)
        out.append(f"| {label} | {median(s['wall_s'] for s in r['scenes']):.0f} | {median(s['peak_rss_mb'] for s in r['scenes']):.0f} | "
                   + " | ".join(f"{median(st[k]):.1f}" if st[k] else "–" for k in _stages(runs)) + " |")
    print("\n".join(out))
    return 0


def _kind(name: str) -> str:
    for k in ("kitchen", "wardrobe", "dresser", "room_door", "mixed", "scene-synthesizer", "scene_synthesizer"):
        if k in name:
            return k.replace("_", "-") if k.startswith("scene") else k
    return "other"


def _kinds(runs: list) -> list[str]:
    seen: list[str] = []
    for _, r in runs:
        for s in r["scenes"]:
            k = _kind(s["scene"])
            if k not in seen:
                seen.append(k)
    return seen


def _stages(runs: list) -> list[str]:
    order = ["perception", "segmentation", "articulation", "assembly", "export", "report"]
    have = {k for _, r in runs for s in r["scenes"] for k in s["stages"]}
    return [k for k in order if k in have]


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
