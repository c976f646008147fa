"""``react3d evaluate PRED_DIR GT_DIR``: the paper's detection and articulation metrics."""

from __future__ import annotations

import argparse
import json

HELP = "Score converted scene(s) against Articulate3D ground truth (F1@0.25/0.5, joint acc, MD, OE, MOD)."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("pred_dir", help="Folder with scene.json (or sub-folders with one each); or an s3://... output "
                                    "or dataset --out (read through each output's pointer, checked against it).")
    p.add_argument("gt_dir", help="Folder with <scan>_parts.json and <scan>_artic.json (or one sub-folder per scan).")
    p.add_argument("--json", dest="json_path", help="Write the metrics JSON here.")
    p.add_argument("--out", help="Also write parts.parquet, scenes.parquet and metrics.md to this folder.")
    p.add_argument("--iou", type=float, nargs="+", help="IoU thresholds (default 0.25 0.5).")


def run(args: argparse.Namespace) -> int:
    from react3d_core.metrics import markdown_table, run_evaluation
    from react3d_core.atomic import write_json

    from tasks import storage

    config = {"iou_thresholds": tuple(args.iou)} if args.iou else None
    pred = str(storage.fetch_outputs(args.pred_dir)) if storage.is_remote(args.pred_dir) else args.pred_dir
    result = run_evaluation(pred, args.gt_dir, args.out, config)
    print(markdown_table(result))
    if args.json_path:
        write_json(args.json_path, result)
    else:
        print(json.dumps(result["aggregate"], indent=1))
    return 0
