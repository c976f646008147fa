"""The ``react3d`` command line. Sub-commands live in ``flows.commands.<name>`` and load lazily,
so ``react3d inspect`` does not import Prefect or torch."""

from __future__ import annotations

import argparse
import errno
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
    "check": "flows.commands.check",
    "view": "flows.commands.view",
    "cache": "flows.commands.cache",
    "server": "flows.commands.server",
}

FLOW_COMMANDS = {"convert", "demo", "convert-dataset"}
"""Commands that run Prefect flows: they use the server named by PREFECT_API_URL (checked first, one-line
error if it does not answer: ``tasks.prefect_env.check_server``), or else react3d's local server, which
the first command starts once its own checks pass and later ones reuse (``flows.local_server``)."""


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

    debug = args.verbose or bool(os.environ.get("REACT3D_DEBUG"))
    try:
        if args.command in FLOW_COMMANDS:
            from tasks.prefect_env import check_server

            if check_server() == "local":
                from flows import local_server

                local_server.plan()
        return int(args._run(args) or 0)
    except React3DError as exc:
        if debug:
            raise
        return _fail(args.command, str(exc), 2, details=len(str(exc).strip().splitlines()) > 1)
    except OSError as exc:
        if debug or exc.errno not in _WRITE_ERRNOS:
            raise
        # read-only output, disk full: the raw error was a traceback (disk full: one 642 KB line)
        where = exc.filename or "output"
        hint = "free some space or choose an --out on another disk" if exc.errno in (errno.ENOSPC, errno.EDQUOT) \
            else "choose an --out folder you can write to"
        return _fail(args.command, f"{where}: {exc.strerror}; {hint}", 2 if exc.errno in _BAD_INPUT_ERRNOS else 1,
                     details=True)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


_WRITE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM}
_BAD_INPUT_ERRNOS = {errno.EROFS, errno.EACCES, errno.EPERM}  # the user chose an --out that cannot be written


def _fail(command: str, message: str, rc: int, details: bool) -> int:
    """Print one line (what, which file, what to do) first; with ``details`` the full message and the
    traceback go to a log file named on that line."""
    lines = message.strip().splitlines() or ["failed"]
    line = lines[0][:400]
    log = _write_log(command, message) if details else None
    print(f"react3d {command}: error: {line}" + (f"  (details: {log})" if log else ""), file=sys.stderr)
    return rc


def _write_log(command: str, message: str) -> str | None:
    """Append the details of a failure to the run's log (where Prefect's error records went too); None
    if it cannot be written."""
    import traceback

    from flows.commands._runconfig import log_path

    path = log_path()
    try:
        with open(path, "a", encoding="utf-8") as fh:
            fh.write(f"react3d {command}: {' '.join(sys.argv)}\n{message}\n\n{traceback.format_exc()}")
    except OSError:
        return None
    return path


if __name__ == "__main__":
    sys.exit(main())
