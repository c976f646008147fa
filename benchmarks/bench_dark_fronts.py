"""Front-level score of the heuristic perception step on scenes whose fronts the depth sensor missed: the
fronts it finds, as boxes, against the ground-truth parts' boxes (no segmentation, articulation or export).

    python3 benchmarks/bench_dark_fronts.py SCENE_DIR... [--heuristic '{"handles": {"knobs": false}}'] [--json F]

``benchmarks/bench_fronts.py`` matches fronts to parts by their mesh faces, but a dark front's scan holds
almost none of its surface (the scene is completed with a slab, ``frames.missed_surface``, whose faces no
ground truth indexes), so here every front is a thin box on its rectangle and is scored as the evaluator
scores such parts: ``front_box_iou`` against the part's box, one-to-one (Hungarian on the IoU), a match
at IoU >= 0.5 (and, reported too, >= 0.25). The scan is completed as ``react3d convert`` does (kept under
``$REACT3D_CACHE/missed_surface``). Minutes for the dark tuning scenes where the full bench takes far longer;
report with the full bench.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def front_box(f: Any) -> Any:
    """A front's rectangle as a 2 cm thick ``OBB`` (sides sorted longest first, as the ground truth's)."""
    import numpy as np

    from react3d_core.data.parts import OBB

    z = np.array([0.0, 0.0, 1.0])
    u = np.asarray(f.u, float) / np.linalg.norm(f.u)
    w, h = f.extent_u[1] - f.extent_u[0], f.extent_v[1] - f.extent_v[0]
    a, b = (z, u) if h >= w else (u, z)
    return OBB(center=tuple(float(x) for x in f.center), axes=(tuple(a), tuple(b), tuple(np.cross(a, b))),
               extents=(max(w, h), min(w, h), 0.02))


def score_scene(scene_dir: str, overrides: dict[str, Any]) -> dict[str, Any]:
    """Build the heuristic on one completed scene (stride 1, as ``react3d bench``) and score its fronts."""
    import numpy as np
    from scipy.optimize import linear_sum_assignment

    from flows.bench.runner import _gt_dir
    from react3d_core.config import PipelineConfig
    from react3d_core.ground_truth.articulate3d import read_articulate3d
    from react3d_core.metrics.scene_metrics import front_box_iou
    from react3d_core.perception.heuristic import HeuristicModel
    from react3d_core.pipeline.steps import load

    t0 = time.perf_counter()
    d = Path(scene_dir)
    gt_dir = _gt_dir(d)
    if gt_dir is None:
        raise SystemExit(f"{d}: no Articulate3D ground truth (articulate3d/*_parts.json)")
    cfg = PipelineConfig().with_overrides({"perception": {"heuristic": overrides}, "frames": {"stride": 1}})
    model = HeuristicModel(load(d, cfg.frames).scene, cfg.perception.heuristic)
    parts = [p for p in read_articulate3d(gt_dir).movable if p.obb is not None]
    boxes = [front_box(f) for f in model.fronts]
    iou = np.array([[front_box_iou(b, p.obb) for b in boxes] for p in parts]).reshape(len(parts), len(boxes))
    rows, cols = linear_sum_assignment(-iou) if iou.size else ([], [])
    matched = [float(iou[i, j]) for i, j in zip(rows, cols)]
    return {"scene": d.name, "n_gt": len(parts), "n_pred": len(boxes),
            "tp50": sum(v >= 0.5 for v in matched), "tp25": sum(v >= 0.25 for v in matched),
            "best_iou": [round(float(r.max()), 3) if len(boxes) else 0.0 for r in iou],
            "seconds": round(time.perf_counter() - t0, 1)}


def f1(tp: int, n_pred: int, n_gt: int) -> float:
    """2 TP / (predictions + ground truth): F1 of a one-to-one matching."""
    return 2.0 * tp / (n_pred + n_gt) if n_pred + n_gt else 0.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="+", help="scene folders (with articulate3d/ ground truth)")
    ap.add_argument("--heuristic", default="{}", help="JSON overrides of perception.heuristic")
    ap.add_argument("--json", help="write the per-scene results here")
    a = ap.parse_args(argv)
    rows = [score_scene(s, json.loads(a.heuristic)) for s in a.scenes]
    for r in rows:
        print(f"{r['scene']:56s} gt {r['n_gt']:3d} fronts {r['n_pred']:3d} F1@0.5 {f1(r['tp50'], r['n_pred'], r['n_gt']):.3f}"
              f" F1@0.25 {f1(r['tp25'], r['n_pred'], r['n_gt']):.3f} ({r['seconds']} s)")
    tp50, tp25 = sum(r["tp50"] for r in rows), sum(r["tp25"] for r in rows)
    npred, ngt = sum(r["n_pred"] for r in rows), sum(r["n_gt"] for r in rows)
    total = {"n_gt": ngt, "n_pred": npred, "f1_50": f1(tp50, npred, ngt), "f1_25": f1(tp25, npred, ngt)}
    print(f"{'ALL':56s} gt {ngt:3d} fronts {npred:3d} F1@0.5 {total['f1_50']:.3f} F1@0.25 {total['f1_25']:.3f}")
    if a.json:
        Path(a.json).write_text(json.dumps({"scenes": rows, "total": total}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
