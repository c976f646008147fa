"""Duplicate removal cost: our bounded two-stage dedup vs the reference's exponential subset search.

    python3 benchmarks/bench_dedup.py [--json bench_dedup.json]

Candidates are vertex-id sets on a strip of cabinets: each cabinet front (a merged part covering
several doors) is overlapped by ``k`` smaller door/drawer parts, plus near-duplicates of some doors
(stage 1), as over-segmenting fusion produces. The reference checks stage 2 by enumerating every
subset of a part's smaller overlapping candidates (2^k unions per part); ours takes one sparse
incidence product for all IoUs and a greedy cover of at most ``max_candidates`` parts (O(n k)).
Table 1: 200 candidates, ours vs the reference (reference time extrapolated from the subsets it
could check within its budget). Table 2: one part with k = 4..24 covering candidates, where 2^k explodes.
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from react3d_core.config import DedupConfig  # noqa: E402
from react3d_core.dedup import dedup_indices  # noqa: E402
from react3d_core.geometry import iou_matrix  # noqa: E402


def make_candidates(n_total: int = 200, k: int = 6, front_size: int = 1200, seed: int = 0) -> list[np.ndarray]:
    """Groups of one merged front and ``k`` overlapping fragments of it (each a window of 25-35 % of
    the front, so IoU >= tau_low and the reference must consider it), every third fragment with a
    near-duplicate (5 % of its vertices swapped: stage 1); ``n_total`` sets."""
    rng = np.random.default_rng(seed)
    sets: list[np.ndarray] = []
    base = 0
    while len(sets) < n_total:
        sets.append(np.arange(base, base + front_size))
        starts = np.linspace(0, front_size * 0.7, k).astype(int)
        for j, st in enumerate(starts):
            if len(sets) >= n_total:
                break
            w = int(front_size * rng.uniform(0.25, 0.35))
            frag = np.arange(base + st, base + min(st + w, front_size))
            sets.append(frag)
            if j % 3 == 0 and len(sets) < n_total:
                drop = rng.choice(len(frag), len(frag) // 20, replace=False)
                sets.append(np.concatenate([np.delete(frag, drop), base + front_size + 10 + np.arange(len(drop))]))
        base += front_size + 1000
    return sets[:n_total]


def reference_stage2_one(big: np.ndarray, small: list[np.ndarray], budget_s: float) -> tuple[float, int, float, bool]:
    """The reference's stage 2 for one part: the best union IoU over every non-empty subset of its
    smaller overlapping candidates. Returns (best IoU, subsets checked, seconds, finished)."""
    t0 = time.perf_counter()
    big = np.unique(big)
    checked, best = 0, 0.0
    for r in range(1, len(small) + 1):
        for combo in itertools.combinations(small, r):
            u = np.unique(np.concatenate(combo))
            inter = np.intersect1d(u, big, assume_unique=True).size
            best = max(best, inter / (len(u) + len(big) - inter))
            checked += 1
            if time.perf_counter() - t0 > budget_s:
                return best, checked, time.perf_counter() - t0, False
    return best, checked, time.perf_counter() - t0, True


def reference_cost(sets: list[np.ndarray], cfg: DedupConfig, budget_s: float) -> dict[str, float]:
    """Extrapolated reference stage-2 time: sum over parts of (2^k - 1) x (measured seconds per subset)."""
    iou = iou_matrix(sets)
    size = np.array([len(np.unique(s)) for s in sets], float)
    ks = [int(((iou[i] >= cfg.tau_low) & (size < size[i])).sum()) for i in range(len(sets))]
    i = int(np.argmax(ks))
    small = [sets[j] for j in np.flatnonzero((iou[i] >= cfg.tau_low) & (size < size[i]))]
    _, checked, sec, _ = reference_stage2_one(sets[i], small, budget_s)
    per_subset = sec / max(checked, 1)
    total_subsets = float(sum(2 ** k - 1 for k in ks))
    return {"max_k": max(ks), "subsets": total_subsets, "seconds_per_subset": per_subset,
            "seconds_extrapolated": total_subsets * per_subset}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=None)
    ap.add_argument("--budget", type=float, default=2.0, help="seconds the reference may run per measurement")
    args = ap.parse_args(argv)
    cfg = DedupConfig()
    res: dict = {"table_200": [], "table_k": []}
    print(f"{'k/front':>8s}{'n':>6s}{'ours (s)':>10s}{'kept':>6s}{'ref subsets':>14s}{'ref (s, extrap.)':>18s}")
    for k in (4, 8, 12, 16, 20):
        sets = make_candidates(200, k)
        t0 = time.perf_counter()
        kept = dedup_indices(sets, cfg)
        ours = time.perf_counter() - t0
        ref = reference_cost(sets, cfg, args.budget)
        res["table_200"].append({"k": k, "n": len(sets), "ours_s": ours, "kept": len(kept), **ref})
        print(f"{k:8d}{len(sets):6d}{ours:10.3f}{len(kept):6d}{ref['subsets']:14.3g}{ref['seconds_extrapolated']:18.3g}")
    print(f"\n{'k':>4s}{'ours (s)':>10s}{'ref subsets':>14s}{'ref (s)':>12s}  (one merged front, k smaller candidates)")
    for k in (4, 8, 12, 16, 20, 24):
        sets = make_candidates(k + 1 + (k + 2) // 3, k)
        t0 = time.perf_counter()
        kept = dedup_indices(sets, cfg)
        ours = time.perf_counter() - t0
        small = [x for x in sets[1:] if len(x) < len(sets[0])]
        best, checked, sec, done = reference_stage2_one(sets[0], small, args.budget)
        n_sub = 2 ** len(small) - 1
        extrap = sec / max(checked, 1) * n_sub
        res["table_k"].append({"k": len(small), "ours_s": ours, "ours_removed_front": 0 not in kept, "ref_checked": checked,
                               "ref_finished": done, "ref_best_iou": best, "ref_s": sec, "ref_s_extrapolated": extrap})
        note = f" ref best IoU {best:.2f}" if done else f" (stopped at budget; {n_sub} subsets -> ~{extrap:.3g} s)"
        print(f"{len(small):4d}{ours:10.4f}{n_sub:14d}{sec:12.3f}  removed front: {0 not in kept}{note}")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main()
