"""Shared CLI options for commands that convert scenes: backend, config file/JSON, refinement, frames."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from react3d_core.errors import ConfigError


def add_pipeline_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--perception", choices=["heuristic", "oracle", "models"], default=None,
                   help="Perception backend (default: heuristic, weight-free).")
    p.add_argument("--config", default=None, help="Pipeline config: a JSON file or an inline JSON object (partial).")
    p.add_argument("--no-refine", action="store_true", help="Keep the predictor's joints (refinement ablation).")
    p.add_argument("--stride", type=int, default=None, help="Use every n-th frame (default from config: 5).")
    p.add_argument("--max-frames", type=int, default=None, help="Cap on frames used.")
    p.add_argument("--formats", default=None, help="Export formats, e.g. urdf,usd,mjcf ('none': no simulator files).")


def pipeline_overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The config dict the flow takes: file/inline JSON first, then the explicit flags."""
    cfg: dict[str, Any] = {}
    if args.config:
        text = args.config.strip()
        try:
            cfg = json.loads(text) if text.startswith("{") else json.loads(Path(text).read_text())
        except FileNotFoundError:
            raise ConfigError(f"{text}: config file not found") from None
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{text}: not valid JSON ({exc})") from None
    def put(path: tuple[str, ...], value: Any) -> None:
        d = cfg
        for k in path[:-1]:
            d = d.setdefault(k, {})
        d[path[-1]] = value
    if args.perception:
        put(("perception", "backend"), args.perception)
    if args.no_refine:
        put(("articulation", "refine"), False)
    if args.stride:
        put(("frames", "stride"), args.stride)
    if args.max_frames:
        put(("frames", "max_frames"), args.max_frames)
    if args.formats:
        put(("export", "formats"), [f.strip() for f in args.formats.split(",") if f.strip() and f.strip() != "none"])
    from react3d_core.config import PipelineConfig

    PipelineConfig().with_overrides(cfg)  # validate now: one clear error before Prefect starts
    return cfg


def run_with_progress(scene: str, out: str, cfg: dict[str, Any], title: str) -> str:
    """Run the convert flow with a rich progress bar (one row per stage)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from tasks import prefect_env

    prefect_env.configure()
    import flows.convert_scene as cs

    with Progress(TextColumn("[bold]{task.description:<13}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  transient=False) as bar:
        rows: dict[str, int] = {}

        def hook(stage: str, done: int, total: int) -> None:
            if stage not in rows:
                rows[stage] = bar.add_task(stage, total=max(total, 1))
            bar.update(rows[stage], completed=done if total else 1, total=max(total, 1))

        bar.console.print(f"[dim]{title}[/dim]")
        cs.PROGRESS_HOOK = hook
        try:
            return cs.convert_scene(scene, out, cfg)
        finally:
            cs.PROGRESS_HOOK = None
