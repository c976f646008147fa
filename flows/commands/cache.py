"""``react3d cache clean [--older-than DAYS] [--store] [--dry-run]``: prune cached task results (Prefect never
deletes them); ``--store`` prunes the store itself (a bucket too) by age and by what no record references."""

from __future__ import annotations

import argparse

HELP = "Show or prune the task cache: Prefect result records and the react3d object store."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("action", choices=["info", "clean"], help="info: sizes; clean: delete.")
    p.add_argument("--older-than", type=float, default=None, help="Only entries not modified for this many days (default: all; "
                   "with --store: result records written this many days ago, default none).")
    p.add_argument("--store", action="store_true",
                   help="Prune the store (REACT3D_STORE: a folder or s3://...; else the local cache) instead of this "
                        "machine's cache: records older than --older-than, then every object and store folder no "
                        "remaining record references (docs/orchestration.md).")
    p.add_argument("--grace", type=float, default=60.0, metavar="MINUTES",
                   help="With --store: keep unreferenced entries written within this many minutes (a running "
                        "conversion writes an object before the record that names it; default 60).")
    p.add_argument("--dry-run", action="store_true", help="List what clean would remove, remove nothing.")


def _roots() -> list:
    import os
    from pathlib import Path

    from tasks.store import cache_root

    prefect_home = Path(os.environ.get("PREFECT_HOME", Path.home() / ".prefect"))
    storage = Path(os.environ.get("PREFECT_LOCAL_STORAGE_PATH", prefect_home / "storage"))
    # collisions/ and reports/: convex decompositions and report pieces cached by content; outputs/: verified
    # local copies of remote outputs that view/export/evaluate read; scans/: scans downloaded from a URL
    return [storage, cache_root() / "objects", cache_root() / "scenes", cache_root() / "quarantine",
            cache_root() / "collisions", cache_root() / "reports", cache_root() / "outputs", cache_root() / "scans"]


def run_store(args: argparse.Namespace) -> int:
    """``cache info|clean --store``: the store's entries by what references them (tasks/store_clean.py)."""
    import time

    from flows.commands._console import wide_console

    from tasks import store_clean

    console = wide_console()
    plan = store_clean.plan_clean(args.older_than, grace_s=max(args.grace, 0.0) * 60)
    gone = sum(e.size for e in plan.remove)
    if args.action == "clean":
        now = time.time()
        for e in plan.remove:
            where = f"{plan.records_at}/{e.rel[len('records/'):]}" if e.kind == "record" else f"{plan.store}/{e.rel}"
            why = f"written {(now - e.mtime) / 86400:.1f} days ago" if e.kind == "record" else "no record references it"
            verb = "would remove" if args.dry_run else "remove"
            console.print(f"{verb} {where}  ({e.kind}, {e.size} bytes, {why})", soft_wrap=True, markup=False, highlight=False)
    summary = (f"{plan.store}: {len(plan.remove)} entries ({gone / 1e6:.1f} MB) {{}}; kept {plan.kept} referenced or "
               f"recent, {plan.records_kept} records ({plan.records_at}); {plan.foreign} files not in react3d's layout left alone")
    if args.action == "info" or args.dry_run:
        console.print(summary.format("unreferenced or expired" if args.action == "info" else "would be removed"),
                      soft_wrap=True, markup=False, highlight=False)
        return 0
    store_clean.apply(plan)
    console.print(summary.format("removed"), soft_wrap=True, markup=False, highlight=False)
    return 0


def run(args: argparse.Namespace) -> int:
    import shutil
    import time

    from flows.commands._console import wide_console

    if args.store:
        return run_store(args)
    console = wide_console()
    cutoff = time.time() - args.older_than * 86400 if args.older_than is not None else None
    for root in _roots():
        if not root.exists():
            console.print(f"{root}: empty")
            continue
        if root.name == "scenes":
            entries = [p for p in root.glob("*/*") if p.is_dir()]
        elif root.name in ("quarantine", "outputs", "scans"):  # corrupt objects moved aside; whole copies
            entries = list(root.iterdir())
        else:
            entries = [p for p in root.rglob("*") if p.is_file()]
        size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
        if args.action == "info":
            console.print(f"{root}: {len(entries)} entries, {size / 1e6:.1f} MB")
            continue
        n = 0
        for p in entries:
            if cutoff is None or p.stat().st_mtime < cutoff:
                if args.dry_run:
                    console.print(f"would remove {p}", soft_wrap=True, markup=False, highlight=False)
                else:
                    shutil.rmtree(p) if p.is_dir() else p.unlink(missing_ok=True)
                n += 1
        console.print(f"{root}: {'would remove' if args.dry_run else 'removed'} {n} of {len(entries)} entries")
    return 0
