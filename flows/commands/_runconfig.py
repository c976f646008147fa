"""Shared CLI options for commands that convert scenes: backend, config file/JSON, refinement, frames."""

from __future__ import annotations

import argparse
import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from react3d_core.errors import ConfigError


def add_pipeline_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--perception", choices=["heuristic", "oracle", "models"], default=None,
                   help="Perception backend (default: heuristic, weight-free).")
    p.add_argument("--config", default=None, help="Pipeline config: a JSON file or an inline JSON object (partial).")
    p.add_argument("--no-refine", action="store_true", help="Keep the predictor's joints (refinement ablation).")
    p.add_argument("--stride", type=int, default=None,
                   help="Use every n-th frame (default: keyframes by camera motion and new surface, cap 300).")
    p.add_argument("--max-frames", type=int, default=None, help="Cap on frames used (evenly subsampled).")
    p.add_argument("--formats", default=None, help="Export formats, e.g. urdf,usd,mjcf ('none': no simulator files).")
    p.add_argument("--physics", default=None,
                   help="Physics check after the export: engines, e.g. mujoco,pybullet,sapien, or 'none' "
                        "(default: the config's physics.engines, MuJoCo; docs/physics.md).")


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
        except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
            raise ConfigError(f"{text}: cannot read the config file ({exc.__class__.__name__})") from None
        if not isinstance(cfg, dict):
            raise ConfigError(f"{text}: the config must be a JSON object ({{\"section\": {{...}}}}), "
                              f"not a {type(cfg).__name__}")
    def put(path: tuple[str, ...], value: Any) -> None:
        d = cfg
        for k in path[:-1]:
            d = d.setdefault(k, {})
        d[path[-1]] = value
    if args.perception:
        put(("perception", "backend"), args.perception)
    if args.no_refine:
        put(("articulation", "refine"), False)
    for flag, value in (("--stride", args.stride), ("--max-frames", args.max_frames)):
        if value is not None and value < 1:  # 0 used to be ignored silently
            raise ConfigError(f"{flag} must be at least 1, got {value}")
    if args.stride is not None:
        put(("frames", "stride"), args.stride)
    if args.max_frames is not None:
        put(("frames", "max_frames"), args.max_frames)
    if args.formats:
        formats = [f.strip().lower() for f in args.formats.split(",") if f.strip() and f.strip().lower() != "none"]
        put(("export", "formats"), formats)
    physics = getattr(args, "physics", None)  # commands without the flag keep the configured check
    if physics:
        engines = [e.strip().lower() for e in physics.split(",") if e.strip()]
        if engines == ["none"]:
            put(("physics", "enabled"), False)
        else:
            from react3d_core.config.physics import ENGINES

            bad = [e for e in engines if e not in ENGINES]
            if bad:
                raise ConfigError(f"--physics: unknown engine(s) {', '.join(bad)}: choose from {', '.join(ENGINES)} or none")
            put(("physics", "enabled"), True)
            put(("physics", "engines"), engines)
    _check_formats(cfg.get("export", {}).get("formats", []) if isinstance(cfg.get("export"), dict) else [])
    from react3d_core.config import PipelineConfig

    PipelineConfig().with_overrides(cfg)  # validate now: one clear error before Prefect starts
    return cfg


def precheck_scene(scene: str, cfg: dict[str, Any]) -> str:
    """Load and validate the scan (frames, depth sizes, JPEGs, units) before Prefect starts, so bad input
    gives one line and no Prefect logs; the flow then reuses what was loaded (per-process caches).
    Returns how the frames were selected ("kept N of M frames: ...")."""
    from tasks import prefect_env

    prefect_env.configure()
    from react3d_core.config import PipelineConfig
    from tasks.scene import loaded_scene

    return loaded_scene(scene, PipelineConfig().with_overrides(cfg).model_dump(mode="json")).scene.frame_selection


def _check_formats(formats: object) -> None:
    """Unknown export formats used to fail only at the export stage, minutes in, with a traceback."""
    from react3d_core.config.export import FORMATS

    bad = [f for f in formats if f not in FORMATS] if isinstance(formats, (list, tuple)) else [formats]
    if bad:
        raise ConfigError(f"unknown export format(s) {', '.join(map(str, bad))}: choose from {', '.join(FORMATS)} or none")


_LOG_PATH: list[str] = []


def log_path() -> str:
    """This process's details log: ``$REACT3D_LOG_DIR`` (default: the temporary folder), created only
    when something is written to it (a failure's traceback, Prefect's error records). Kept here, not in
    ``flows.cli``, which runs as ``__main__`` under ``python -m`` (a second module copy, a second path)."""
    if not _LOG_PATH:
        import os
        import tempfile
        import time

        folder = os.environ.get("REACT3D_LOG_DIR") or tempfile.gettempdir()
        _LOG_PATH.append(os.path.join(folder, f"react3d-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"))
    return _LOG_PATH[0]


@contextlib.contextmanager
def prefect_errors_to_log(path: str) -> Iterator[None]:
    """Prefect reports a failed task or flow as ERROR records with tracebacks on the console (84-113
    lines before the one that says what to do); during a CLI run they go to the log file ``path``
    instead and the CLI prints one line naming it. Warnings still reach the console."""
    import logging

    class _NoPrefectErrors(logging.Filter):
        def filter(self, record: logging.LogRecord) -> bool:
            return not (record.levelno >= logging.ERROR and record.name.startswith("prefect"))

    file_handler = logging.FileHandler(path, delay=True, encoding="utf-8")
    file_handler.setLevel(logging.ERROR)
    file_handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    from prefect.logging.configuration import ensure_logging_setup

    ensure_logging_setup()  # Prefect configures logging lazily; its console handler sits on the root logger
    drop = _NoPrefectErrors()
    names = [n for n in logging.Logger.manager.loggerDict if n == "prefect" or n.startswith("prefect.")]
    touched: list[tuple[logging.Logger, list[logging.Handler]]] = []
    for logger in [logging.getLogger()] + [logging.getLogger(n) for n in names]:
        consoles = [h for h in logger.handlers
                    if isinstance(h, logging.StreamHandler) and not isinstance(h, logging.FileHandler)]
        if consoles:
            for h in consoles:
                h.addFilter(drop)
            logger.addHandler(file_handler)
            touched.append((logger, consoles))
    try:
        yield
    finally:
        for logger, consoles in touched:
            for h in consoles:
                h.removeFilter(drop)
            logger.removeHandler(file_handler)
        file_handler.close()


def run_with_progress(scene: str, out: str, cfg: dict[str, Any], title: str) -> str:
    """Run the convert flow with a rich progress bar (one row per stage)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from flows import local_server
    from tasks import prefect_env

    prefect_env.configure()
    local_server.attach()  # a server that has to start does so while the flow's modules load
    import flows.convert_scene as cs

    local_server.ready()

    with Progress(TextColumn("[bold]{task.description:<13}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  transient=False) as bar:
        rows: dict[str, int] = {}

        def hook(stage: str, done: int, total: int) -> None:
            if stage not in rows:
                rows[stage] = bar.add_task(stage, total=max(total, 1))
            bar.update(rows[stage], completed=done if total else 1, total=max(total, 1))

        bar.console.print(f"[dim]{title}[/dim]")
        with prefect_errors_to_log(log_path()):
            return cs.convert_scene(scene, out, cfg, progress=hook)
