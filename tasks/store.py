"""Content-addressed object store for task results: tasks return small *handles*, never arrays.

A handle is ``{"sha256": ..., "path": ..., "kind": ...}``; the file lives under
``$REACT3D_CACHE/objects/<aa>/<sha256>.npz`` (default ``~/.cache/react3d``), so a cached handle
stays valid whatever output folder a later run writes to. Put the store on shared storage at the
same absolute path for multi-machine workers. ``react3d cache clean`` prunes it with Prefect's records.
"""

from __future__ import annotations

import hashlib
import os
from functools import lru_cache
from pathlib import Path
from typing import Any

from react3d_core.atomic import atomic_path
from react3d_core.errors import InputError

from .serialize import dumps, loads


def cache_root() -> Path:
    return Path(os.environ.get("REACT3D_CACHE", Path.home() / ".cache" / "react3d"))


def put(obj: Any, kind: str) -> dict[str, str]:
    """Serialize ``obj`` into the store; returns its handle."""
    data = dumps(obj)
    sha = hashlib.sha256(data).hexdigest()
    path = cache_root() / "objects" / sha[:2] / f"{sha}.npz"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            tmp.write_bytes(data)
    return {"sha256": sha, "path": str(path), "kind": kind}


def get(handle: dict[str, str], cache: bool = True) -> Any:
    """Load the object behind a handle (clear error if the store was cleaned under a cached record).

    The last few decoded objects are kept per process: per-part tasks read the same perception results.
    ``cache=False`` decodes without keeping it (a fan-in that reads every batch once).
    """
    path = Path(handle["path"])
    if not path.is_file():
        raise InputError(path, f"cached {handle.get('kind', 'result')} is gone from the store; "
                               "run `react3d cache clean` (drops stale records) and convert again")
    if not cache:
        return loads(path.read_bytes())
    return _get_cached(handle["sha256"], str(path))


@lru_cache(maxsize=24)
def _get_cached(sha: str, path: str) -> Any:
    return loads(Path(path).read_bytes())


def file_sha256(path: str | Path, chunk: int = 1 << 20) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while block := fh.read(chunk):
            h.update(block)
    return h.hexdigest()


def tree_fingerprint(root: str | Path, exclude: tuple[str, ...] = ()) -> str:
    """Hash of every file's relative path and bytes under ``root`` (hidden files and ``exclude`` skipped)."""
    root = Path(root)
    h = hashlib.sha256()
    for p in sorted(root.rglob("*")):
        rel = p.relative_to(root).as_posix()
        if not p.is_file() or any(part.startswith(".") for part in p.relative_to(root).parts) or rel.startswith(exclude):
            continue
        h.update(rel.encode())
        h.update(file_sha256(p).encode())
    return h.hexdigest()
