"""The ``react3d`` command line. Sub-commands live in ``flows.commands.<name>`` and load lazily,
so ``react3d inspect`` does not import Prefect or torch."""

from __future__ import annotations

import argparse
import importlib
import os
import sys

COMMANDS: dict[str, str] = {
    "demo": "flows.commands.demo",
    "convert": "flows.commands.convert",
    "convert-dataset": "flows.commands.convert_dataset",
    "synth": "flows.commands.synth",
    "inspect": "flows.commands.inspect",
    "evaluate": "flows.commands.evaluate",
    "bench": "flows.commands.bench",
    "export": "flows.commands.export",
    "view": "flows.commands.view",
    "cache": "flows.commands.cache",
}


def _load(name: str):  # noqa: ANN202
    try:
        return importlib.import_module(COMMANDS[name])
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.startswith("flows.commands"):
            return None
        raise


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="react3d", description="Static indoor scan -> simulation-ready interactive scene.")
    parser.add_argument("--verbose", action="store_true", help="Show full tracebacks on errors.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        mod = _load(name)
        if mod is None:
            continue
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    from react3d_core.errors import React3DError

    try:
        return int(args._run(args) or 0)
    except React3DError as exc:
        if args.verbose or os.environ.get("REACT3D_DEBUG"):
            raise
        print(f"react3d {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
