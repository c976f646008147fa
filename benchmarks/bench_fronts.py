"""Front-level score of the heuristic perception step (no segmentation, articulation or export):
the fronts it finds against the ground-truth parts, per scene and in total.

    python3 benchmarks/bench_fronts.py --scenes tuning_realistic_2 [--heuristic '{"handles": {"protrusion_from_surface": true}}'] \
        [--out /tmp/fronts] [--jobs 2] [--json F] [--dump DIR]

``--scenes`` is a set (flows/bench/sets/NAME.json; missing scenes are generated under ``--out``) or a glob
of scene folders. Matching: ``react3d_core.metrics.front_match`` (area IoU >= 0.5, one-to-one); a front
with a joint counts as typed right when its joint type is the part's. Minutes per set where the full
``react3d bench`` takes an hour, for deciding thresholds on the tuning sets; report with the full bench.
Prints a table and writes JSON. ``--dump DIR`` also writes every front found (plane, rectangle, faces,
handles, kind, joint; exact floats) to DIR/<scene>.json, so two versions of the code can be diffed front by front.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from multiprocessing import get_context
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def front_records(model: Any) -> list[dict[str, Any]]:
    """Every front of a built ``HeuristicModel`` as JSON-exact records (floats round-trip; face lists as
    count + SHA-256): what a refactor of the heuristic must leave unchanged."""
    import hashlib

    import numpy as np

    def arr(a: Any) -> Any:
        return None if a is None else np.asarray(a, float).tolist()

    def digest(a: Any) -> Any:
        if a is None:
            return None
        a = np.ascontiguousarray(a)
        return [int(a.shape[0]), a.dtype.str, hashlib.sha256(a.tobytes()).hexdigest()]

    out = []
    for f in model.fronts:
        j = f.articulation
        out.append({"facet": int(f.facet), "handle_facets": [int(k) for k in f.handle_facets],
                    "frame_facets": [int(k) for k in f.frame_facets], "center": arr(f.center), "n_out": arr(f.n_out),
                    "u": arr(f.u), "extent_u": arr(f.extent_u), "extent_v": arr(f.extent_v), "kind": f.kind,
                    "faces": digest(f.faces), "handle_points": digest(f.handle_points),
                    "shadow_points": digest(f.shadow_points),
                    "joint": None if j is None else {"type": j.joint_type, "axis": arr(j.axis), "origin": arr(j.origin),
                                                     "lower": float(j.lower), "upper": float(j.upper)}})
    return out


def score_scene(scene_dir: str, overrides: dict[str, Any], dump: str | None = None) -> dict[str, Any]:
    """Build the heuristic on one scene folder (stride 1, as ``react3d bench``) and score its fronts;
    ``dump``: a folder to write every front to (``front_records``)."""
    from flows.bench.miss_causes import gt_part_faces
    from flows.bench.runner import _gt_dir
    from react3d_core.config import PipelineConfig
    from react3d_core.ground_truth.articulate3d import read_articulate3d
    from react3d_core.metrics.front_match import match_fronts
    from react3d_core.perception.heuristic import HeuristicModel
    from react3d_core.scene_io import load_scene

    t0 = time.perf_counter()
    d = Path(scene_dir)
    gt_dir = _gt_dir(d)
    if gt_dir is None:
        raise SystemExit(f"{d}: no Articulate3D ground truth (articulate3d/*_parts.json)")
    cfg = PipelineConfig().with_overrides({"perception": {"heuristic": overrides}, "frames": {"stride": 1}})
    model = HeuristicModel(load_scene(d, cfg.frames), cfg.perception.heuristic)
    gt = read_articulate3d(gt_dir)
    faces = gt_part_faces(gt)  # each movable part with its handles
    s = match_fronts([faces[p.part_id] for p in gt.movable], [fr.faces for fr in model.fronts], model.mesh.face_areas)
    typed = sum(1 for i, j, _ in s.pairs if model.fronts[j].articulation is not None
                and model.fronts[j].articulation.joint_type == gt.movable[i].articulation.joint_type)
    if dump:
        from react3d_core.atomic import write_json

        write_json(Path(dump) / f"{d.name}.json", front_records(model))
    return {"scene": d.name, "tp": s.tp, "pred": s.n_pred, "gt": s.n_gt, "precision": s.precision, "recall": s.recall,
            "f1": s.f1, "joint_type_ok": typed, "seconds": time.perf_counter() - t0}


def _scene_dirs(spec: str, out: Path) -> list[str]:
    from flows.bench.runner import ensure_scene, load_spec

    return [str(ensure_scene(e)) for e in load_spec(spec, out)]


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", required=True)
    ap.add_argument("--heuristic", default="{}", help="JSON overrides of perception.heuristic")
    ap.add_argument("--out", default="/tmp/react3d_bench_fronts", help="where generated scenes go")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", dest="json_path")
    ap.add_argument("--dump", help="folder: every front found, per scene (exact, for diffing two versions)")
    a = ap.parse_args(argv)
    overrides = json.loads(a.heuristic)
    dirs = _scene_dirs(a.scenes, Path(a.out))
    with get_context("spawn").Pool(max(1, a.jobs)) as pool:
        rows = pool.starmap(score_scene, [(d, overrides, a.dump) for d in dirs])
    tp, pred, gt = (sum(r[k] for r in rows) for k in ("tp", "pred", "gt"))
    total = {"tp": tp, "pred": pred, "gt": gt, "precision": tp / pred if pred else 0.0, "recall": tp / gt if gt else 0.0,
             "f1": 2 * tp / (pred + gt) if pred + gt else 0.0,
             "joint_type_accuracy": sum(r["joint_type_ok"] for r in rows) / tp if tp else 0.0}
    print(f"{'scene':58s} {'tp':>4s} {'pred':>5s} {'gt':>4s} {'F1':>6s}")
    for r in rows:
        print(f"{r['scene']:58s} {r['tp']:4d} {r['pred']:5d} {r['gt']:4d} {r['f1']:6.3f}")
    print(f"{'TOTAL':58s} {tp:4d} {pred:5d} {gt:4d} {total['f1']:6.3f}  (P {total['precision']:.3f}, R {total['recall']:.3f}, "
          f"joint type {total['joint_type_accuracy']:.3f})")
    result = {"scenes": a.scenes, "heuristic_overrides": overrides, "rows": rows, "total": total}
    if a.json_path:
        from react3d_core.atomic import write_json

        write_json(a.json_path, result)
    return result


if __name__ == "__main__":
    main()
