"""``react3d cache clean [--older-than DAYS]``: prune cached task results (Prefect never deletes them)."""

from __future__ import annotations

import argparse

HELP = "Show or prune the task cache: Prefect result records and the react3d object store."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("action", choices=["info", "clean"], help="info: sizes; clean: delete.")
    p.add_argument("--older-than", type=float, default=None, help="Only entries not modified for this many days (default: all).")


def _roots() -> list:
    import os
    from pathlib import Path

    from tasks.store import cache_root

    prefect_home = Path(os.environ.get("PREFECT_HOME", Path.home() / ".prefect"))
    storage = Path(os.environ.get("PREFECT_LOCAL_STORAGE_PATH", prefect_home / "storage"))
    # collisions/ and reports/: convex decompositions and report pieces cached by content
    return [storage, cache_root() / "objects", cache_root() / "scenes", cache_root() / "quarantine",
            cache_root() / "collisions", cache_root() / "reports"]


def run(args: argparse.Namespace) -> int:
    import shutil
    import time

    from rich.console import Console

    console = Console()
    cutoff = time.time() - args.older_than * 86400 if args.older_than is not None else None
    for root in _roots():
        if not root.exists():
            console.print(f"{root}: empty")
            continue
        if root.name == "scenes":
            entries = [p for p in root.glob("*/*") if p.is_dir()]
        elif root.name == "quarantine":  # corrupt objects and folders moved aside, each with its seal
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
                shutil.rmtree(p) if p.is_dir() else p.unlink(missing_ok=True)
                n += 1
        console.print(f"{root}: removed {n} of {len(entries)} entries")
    return 0
