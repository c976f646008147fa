"""Work folders of the benchmarks: made by a benchmark (a marker file says so) or refused.

Benchmarks clear their work folder between runs; a ``--work`` pointing at a folder the user filled
must never be wiped, so only an empty or missing folder, or one carrying the marker, is used.
"""

from __future__ import annotations

import shutil
from pathlib import Path

MARKER = ".react3d-bench"


def bench_workdir(path: Path, fresh: bool = False) -> Path:
    """``path`` as a benchmark work folder (created and marked when new); with ``fresh`` everything in
    it but the marker is removed. A non-empty folder without the marker is a SystemExit, untouched."""
    path = Path(path)
    if path.is_dir() and any(path.iterdir()) and not (path / MARKER).is_file():
        raise SystemExit(f"{path}: not empty and not made by a react3d benchmark; choose another --work")
    if path.exists() and not path.is_dir():
        raise SystemExit(f"{path}: is a file; choose another --work")
    path.mkdir(parents=True, exist_ok=True)
    (path / MARKER).touch()
    if fresh:
        for entry in path.iterdir():
            if entry.name != MARKER:
                shutil.rmtree(entry) if entry.is_dir() and not entry.is_symlink() else entry.unlink()
    return path
