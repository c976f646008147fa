"""``react3d check OUT``: drive every exported joint in MuJoCo, PyBullet and SAPIEN with collisions on,
probe cavities and fronts; a table in the terminal, JSON on disk (docs/physics.md)."""

from __future__ import annotations

import argparse

HELP = ("Physics check of a converted scene: drive each joint to its limit and back in MuJoCo / PyBullet / SAPIEN "
        "(collisions and gravity on), drop probes into open cavities and against closed fronts.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", help="Output folder of `react3d convert` (holds scene.json and export/).")
    p.add_argument("--engines", default=None,
                   help="Comma-separated engines: mujoco, pybullet, sapien (default: all three; a missing one is skipped).")
    p.add_argument("--json", default=None, help="Where to write the full result (default OUT/physics_check.json).")
    p.add_argument("--strict", action="store_true", help="Exit 1 when any joint or probe fails (or an engine errs).")
    p.add_argument("--no-probes", action="store_true", help="Drive the joints only.")
    p.add_argument("--config", default=None, help="Pipeline config JSON; its 'physics' section sets gains, times, thresholds.")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from rich.console import Console

    from flows.commands._console import wide_console
    from react3d_core.atomic import is_react3d_output
    from react3d_core.config import PipelineConfig
    from react3d_core.config.physics import ENGINES
    from react3d_core.errors import ConfigError, InputError
    from react3d_core.physics import DEFAULT_JSON, check_output, load_output, write_check
    from react3d_core.physics.table import render

    cfg = PipelineConfig.from_file(args.config).physics if args.config else PipelineConfig().physics
    engines = tuple(e.strip().lower() for e in args.engines.split(",") if e.strip()) if args.engines else ENGINES
    bad = [e for e in engines if e not in ENGINES]
    if bad or not engines:
        raise ConfigError(f"--engines: unknown engine(s) {bad or '(none)'}; choose from {', '.join(ENGINES)}")
    if args.no_probes:
        cfg = cfg.model_copy(update={"probes": False})
    root, _ = load_output(args.out)  # one-line error before any engine loads
    target = Path(args.json) if args.json else root / DEFAULT_JSON
    if not args.json and target.exists() and not is_react3d_output(root):
        raise InputError(target, "exists in a folder react3d did not write; choose where to write with --json")
    err = Console(stderr=True)
    with err.status("physics check") as status:
        check = check_output(root, cfg, engines, progress=lambda e, what: status.update(f"{e}: {what}"))
    render(check, wide_console())
    write_check(check, target)
    print(f"json: {target}")
    return 1 if args.strict and not check.passed else 0
