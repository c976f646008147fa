"""The metric tables of ``react3d evaluate --out``: per-part and per-scene parquet, and metrics.md laid out
like the paper's tables. (The per-scene ``report.html`` is the viewer's: ``react3d_core.viewer.report``.)"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from ..atomic import atomic_path, write_text
from .scene_metrics import SceneMetrics, to_json_dict


def write_parts_parquet(path: str | Path, scenes: list[SceneMetrics]) -> Path:
    """One row per (scene, tau, GT part)."""
    rows = [r for s in scenes for r in s.parts]
    cols = ["scene", "tau", "gt_part", "gt_type", "diag", "matched", "pred", "iou", "pred_type", "type_ok", "oe", "md", "mo", "mod",
            "scored_by"]
    table = pa.table({c: [r[c] for r in rows] for c in cols}) if rows else pa.table({c: pa.array([], pa.null()) for c in cols})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return Path(path)


def write_scenes_parquet(path: str | Path, scenes: list[SceneMetrics]) -> Path:
    """One row per (scene, tau) with the ten metrics and the run's cost."""
    d = to_json_dict(scenes)
    rows: list[dict[str, Any]] = []
    for s in d["scenes"]:
        for tau in d["aggregate"]:
            rows.append({"scene": s["scene"], "tau": float(tau), "n_gt": s["n_gt"], "n_pred": s["n_pred"], "frames": s["frames"],
                         "faces": s["faces"], "wall_s": s["wall_s"], "peak_rss_mb": s["peak_rss_mb"], **s[tau]})
    with atomic_path(path) as tmp:
        pq.write_table(pa.Table.from_pylist(rows), tmp)
    return Path(path)


def _fmt(v: float | None, kind: str) -> str:
    if v is None:
        return "–"
    if kind == "pct":
        return f"{100 * v:.1f}"
    if kind == "f":
        return f"{v:.3f}"
    return f"{v:.2f}"


def markdown_table(result: dict[str, Any], method: str = "REACT3D") -> str:
    """Two tables as in the paper: detection F1 per tau, and articulation + MOD at each tau."""
    agg = result["aggregate"]
    taus = list(agg)
    lines = ["| Method | " + " | ".join(f"F1@{t}" for t in taus) + " | " + " | ".join(f"P@{t} | R@{t}" for t in taus) + " |",
             "|---" * (1 + 3 * len(taus)) + "|",
             f"| {method} | " + " | ".join(_fmt(agg[t]["f1"], "f") for t in taus) + " | "
             + " | ".join(f"{_fmt(agg[t]['precision'], 'f')} | {_fmt(agg[t]['recall'], 'f')}" for t in taus) + " |", ""]
    lines += ["| Method | τ | Joint acc (%) ↑ | MD (m) ↓ | OE (°) ↓ | PDet (%) | +M (%) | +MO (%) | +MOD (%) |",
              "|---|---|---|---|---|---|---|---|---|"]
    for t in taus:
        a = agg[t]
        lines.append(f"| {method} | {t} | {_fmt(a['joint_acc'], 'pct')} | {_fmt(a['md'], 'f')} | {_fmt(a['oe'], 'd')} | "
                     f"{_fmt(a['pdet'], 'pct')} | {_fmt(a['m'], 'pct')} | {_fmt(a['mo'], 'pct')} | {_fmt(a['mod'], 'pct')} |")
    return "\n".join(lines) + "\n"


def write_tables(out_dir: str | Path, scenes: list[SceneMetrics], method: str = "REACT3D") -> dict[str, Path]:
    """parts.parquet, scenes.parquet and metrics.md in ``out_dir``."""
    out_dir = Path(out_dir)
    return {
        "parts": write_parts_parquet(out_dir / "parts.parquet", scenes),
        "scenes": write_scenes_parquet(out_dir / "scenes.parquet", scenes),
        "markdown": write_text(out_dir / "metrics.md", markdown_table(to_json_dict(scenes), method)),
    }
