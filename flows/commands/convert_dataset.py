"""``react3d convert-dataset ROOT --out OUT``: every scene under ROOT; failures reported, never fatal."""

from __future__ import annotations

import argparse

from ._runconfig import add_pipeline_arguments

HELP = "Convert every scene folder under ROOT (or --scenes / --glob); ends with a table of succeeded/failed scenes."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("root", help="Dataset folder with one sub-folder per scene, or its URL (s3://bucket/scans: each "
                                "worker downloads a scene into its bounded scan cache, REACT3D_SCAN_CACHE_GB).")
    p.add_argument("--out", required=True, help="Output root: one folder per scene.")
    p.add_argument("--scenes", nargs="*", default=None, help="Scene ids (sub-folder names).")
    p.add_argument("--glob", default=None, help="Pattern on sub-folder names, e.g. '0a*'.")
    p.add_argument("--concurrency", type=int, default=1, help="Scenes converted at the same time (with --deployment: flow runs in flight).")
    p.add_argument("--deployment", default=None,
                   help="Fan scenes out to the workers of a deployment, e.g. react3d-convert-scene/convert-scene "
                        "(needs PREFECT_API_URL of a server; docs/orchestration.md). Default: in this process.")
    p.add_argument("--max-attempts", type=int, default=3,
                   help="With --deployment: runs per scene when a run crashes (worker died) or times out; failed scenes are not retried.")
    p.add_argument("--start-timeout", type=_seconds, default=None, metavar="S",
                   help="With --deployment: cancel a scene's run that no worker has started within S seconds, "
                        "and submit it again while attempts remain (default: wait for ever).")
    p.add_argument("--run-timeout", type=_seconds, default=None, metavar="S",
                   help="With --deployment: cancel a scene's run not finished S seconds after it started, "
                        "and submit it again while attempts remain (default: no limit).")
    add_pipeline_arguments(p)


def _seconds(text: str) -> float:
    """A positive number of seconds (argparse type)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number of seconds: {text!r}") from None
    if not v > 0:
        raise argparse.ArgumentTypeError(f"must be > 0 seconds: {text!r}")
    return v


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from flows.commands._console import wide_console
    from rich.table import Table

    from tasks import prefect_env

    from ._runconfig import pipeline_overrides

    prefect_env.configure()
    from flows.convert_dataset import convert_dataset

    from flows.convert_dataset import check_dataset_outputs

    if (args.start_timeout or args.run_timeout) and not args.deployment:
        from react3d_core.errors import InputError

        raise InputError(None, "--start-timeout and --run-timeout apply to runs on workers: add --deployment")
    cfg = pipeline_overrides(args)
    check_dataset_outputs(args.root, args.scenes, args.glob, args.out)  # before any scene runs
    from flows import local_server

    local_server.ready()
    from tasks import storage

    storage.ensure_result_block()  # REACT3D_STORE=s3://...: result records beside the store (no-op otherwise)
    console = wide_console()
    from ._runconfig import log_path, prefect_errors_to_log

    # a failed scene is one row of the table below; Prefect's tracebacks for it go to the log file
    with console.status("converting scenes (per-scene progress in the Prefect UI when a server is configured)"), \
            prefect_errors_to_log(log_path()):
        rows = convert_dataset(args.root, args.scenes, args.glob, args.out, cfg, args.concurrency,
                               args.deployment, args.max_attempts, args.start_timeout, args.run_timeout)
    t = Table(title=f"{sum(r['status'] == 'ok' for r in rows)}/{len(rows)} scenes converted")
    cols = ("scene", "status", "parts", "seconds", "retries", "worker", "error") if args.deployment else \
        ("scene", "status", "parts", "seconds", "error")
    for c in cols:
        t.add_column(c)
    for r in rows:
        cells = {**{k: str(r.get(k, "")) for k in cols}, "seconds": f"{r['seconds']:.1f}",
                 "status": "[green]ok[/green]" if r["status"] == "ok" else "[red]failed[/red]"}
        t.add_row(*(cells[c] for c in cols))
    console.print(t)
    if Path(log_path()).is_file():
        console.print(f"details of the failures: {log_path()}")
    return 0 if all(r["status"] == "ok" for r in rows) else 1
