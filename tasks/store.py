"""Content-addressed object store for task results: tasks return small *handles*, never arrays.

A handle is ``{"sha256": ..., "path": ..., "kind": ...}`` with ``path`` relative to the store root
(``objects/<aa>/<sha256>.npz``), so a cached handle stays valid whatever output folder a later run
writes to and wherever a worker mounts the store. The store is chosen by ``REACT3D_STORE``
(tasks/storage.py: a local folder, a shared mount, or ``s3://...`` mirrored in each worker's
``REACT3D_CACHE``). ``react3d cache clean`` prunes the local folder with Prefect's records;
``react3d cache clean --store`` prunes the store itself by what no record references (tasks/store_clean.py).

Nothing read from the store is trusted blindly: objects are checked against their sha256 on every read,
store folders (assembly, export) against the seal written beside them; a corrupt one is quarantined
with one warning line and recomputed (docs/reliability.md).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import shutil
import socket
import time
import threading
from collections import OrderedDict
from pathlib import Path
from typing import Any

from react3d_core.atomic import atomic_path, pid_alive
from react3d_core.errors import InputError

from . import storage
from .serialize import dumps, loads, loads_sized


def cache_root() -> Path:
    """This worker's local root of the store (see :func:`tasks.storage.cache_root`)."""
    return storage.cache_root()


def resolve(path: str | Path) -> Path:
    """A handle's path on this worker: relative ones (current) under the store root, absolute ones as they are."""
    return cache_root() / path


def relative(path: Path) -> str:
    """``path`` inside the store as the relative POSIX path that handles and records carry."""
    return path.relative_to(cache_root()).as_posix()


def put(obj: Any, kind: str) -> dict[str, str]:
    """Serialize ``obj`` into the store; returns its handle.

    An object already in the store is kept only if its bytes still hash to its name: a corrupt copy is
    quarantined and rewritten, so recomputing heals the store."""
    sweep_stale()
    data = dumps(obj)
    sha = hashlib.sha256(data).hexdigest()
    path = cache_root() / "objects" / sha[:2] / f"{sha}.npz"
    if path.exists() and not _unchanged_since_verified(path) and not _file_matches(path, sha, len(data)):
        quarantine(path, "its bytes do not match its sha256")
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            tmp.write_bytes(data)
    else:  # reused: its age is its last use, so `cache clean --store` keeps it until its record is written
        try:
            os.utime(path)
        except OSError:
            pass
    _remember(path)
    storage.push_file(path, relative(path))
    return {"sha256": sha, "path": relative(path), "kind": kind}


def get(handle: dict[str, str], cache: bool = True) -> Any:
    """Load the object behind a handle, after checking its bytes against the handle's sha256.

    A missing or corrupt object raises :class:`CorruptObjectError` (one line; a corrupt file is moved to
    the quarantine first, so the next run recomputes it instead of failing again). The last few decoded
    objects are kept per process: per-part tasks read the same perception results. ``cache=False``
    decodes without keeping it (a fan-in that reads every batch once).
    """
    path = resolve(handle["path"])
    if not path.is_file() and not _pull_object(path):
        raise CorruptObjectError(path, f"cached {handle.get('kind', 'result')} is gone from the store; "
                                       "run `react3d cache clean` (drops stale records) and convert again")
    if not cache:
        return loads(_read_verified(path, handle["sha256"]))
    return _get_cached(handle["sha256"], str(path))


DECODED_CACHE_BYTES = int(float(os.environ.get("REACT3D_DECODED_CACHE_MB", "512")) * 2**20)
"""Budget of the per-process cache of decoded objects. It was 24 objects whatever their size: 24
perception batches of a 300-frame capture (full-resolution masks) held 2-3 GB during articulation."""
_decoded: OrderedDict[str, tuple[Any, int]] = OrderedDict()
_decoded_lock = threading.Lock()


def _get_cached(sha: str, path: str) -> Any:
    """Decoded objects, most recently used last, within :data:`DECODED_CACHE_BYTES`."""
    with _decoded_lock:
        if sha in _decoded:
            _decoded.move_to_end(sha)
            return _decoded[sha][0]
    obj, size = loads_sized(_read_verified(Path(path), sha))
    if size <= DECODED_CACHE_BYTES:
        with _decoded_lock:
            _decoded[sha] = (obj, size)
            total = sum(n for _, n in _decoded.values())
            while total > DECODED_CACHE_BYTES and len(_decoded) > 1:
                _, (_, n) = _decoded.popitem(last=False)
                total -= n
    return obj


def clear_decoded() -> None:
    """Forget every decoded object (a quarantined file must not be served from memory)."""
    with _decoded_lock:
        _decoded.clear()


def decoded_cache_bytes() -> int:
    """What the decoded-object cache holds now (bytes)."""
    with _decoded_lock:
        return sum(n for _, n in _decoded.values())


def _pull_object(path: Path) -> bool:
    """Fetch an object this worker lacks from the remote store (False: no remote, or not there either)."""
    try:
        return storage.pull_file(relative(path), path)
    except ValueError:  # outside the store root
        return False


def _pull_dir(path: Path) -> bool:
    try:
        return storage.pull_dir(relative(path), path, SEAL_SUFFIX)
    except ValueError:
        return False


def _read_verified(path: Path, sha: str) -> bytes:
    data = path.read_bytes()
    if hashlib.sha256(data).hexdigest() != sha:
        quarantine(path, "its bytes do not match its sha256")
        raise CorruptObjectError(path, "cached object was corrupt (sha256 mismatch) and has been quarantined; "
                                       "run the command again to recompute it")
    _remember(path)
    return data


# --- integrity: verification, seals of store folders, quarantine, stale temporaries -------------------

SEAL_SUFFIX = ".seal.json"
"""``<folder>.seal.json`` beside a store folder: the sha256 of every file in it, written when it is made."""

STALE_TMP_SECONDS = 6 * 3600
"""Age after which a temporary without a process id in its name (older releases, ``atomic_path``) is stale."""

_log = logging.getLogger("react3d.cache")
_verified: dict[str, Any] = {}  # path -> stat signature at the last successful verification
_TMP_PID = re.compile(r"^\..+\.(tmp|old)-(?P<pid>\d+)(@(?P<host>[0-9a-f]{8})-[0-9a-f]+)?$")


class CorruptObjectError(InputError):
    """An object or folder of the store that is gone or no longer matches its recorded sha256."""


def _signature(path: Path) -> Any:
    if path.is_dir():
        return tuple((p.relative_to(path).as_posix(), _stat_sig(p)) for p in sorted(path.rglob("*")) if p.is_file())
    return _stat_sig(path)


def _stat_sig(path: Path) -> tuple[int, int, int]:
    st = path.stat()
    return (st.st_size, st.st_mtime_ns, st.st_ino)


def _remember(path: Path) -> None:
    try:
        _verified[str(path)] = _signature(path)
    except OSError:
        _verified.pop(str(path), None)


def _unchanged_since_verified(path: Path) -> bool:
    try:
        return str(path) in _verified and _verified[str(path)] == _signature(path)
    except OSError:
        return False


def _file_matches(path: Path, sha: str, size: int | None = None) -> bool:
    try:
        if size is not None and path.stat().st_size != size:
            return False
        return file_sha256(path) == sha
    except OSError:
        return False


def quarantine(path: Path, why: str) -> Path | None:
    """Move a corrupt object (or store folder, with its seal) to ``$REACT3D_CACHE/quarantine``; one warning line."""
    qdir = cache_root() / "quarantine"
    qdir.mkdir(parents=True, exist_ok=True)
    dest = qdir / f"{path.name}.{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}"
    _verified.pop(str(path), None)
    clear_decoded()
    try:
        os.replace(path, dest)
    except FileNotFoundError:
        return None
    seal = path.with_name(path.name + SEAL_SUFFIX)
    if seal.exists():
        os.replace(seal, dest.with_name(dest.name + SEAL_SUFFIX))
    _log.warning("react3d: cached %s: %s; moved to %s and recomputing", path, why, dest)
    return dest


def seal_dir(path: str | Path) -> Path:
    """Record the sha256 of every file of a finished store folder beside it (``<folder>.seal.json``).

    Called right after the folder is renamed into place; :func:`verify_dir` checks it on every cache hit."""
    path = Path(path)
    sweep_stale()
    files = {p.relative_to(path).as_posix(): file_sha256(p) for p in sorted(path.rglob("*")) if p.is_file()}
    seal = path.with_name(path.name + SEAL_SUFFIX)
    with atomic_path(seal) as tmp:
        tmp.write_text(json.dumps({"version": 1, "files": files}, indent=0), encoding="utf-8")
    _remember(path)
    if storage.remote_root() is not None:
        storage.push_dir(path, relative(path), seal)
    return seal


def verify_dir(path: str | Path) -> None:
    """Check a store folder against its seal; a corrupt, unsealed or incomplete one is quarantined.

    Raises :class:`CorruptObjectError`. Unchanged folders verified before in this process are not rehashed."""
    path = Path(path)
    if _unchanged_since_verified(path):
        return
    if not path.is_dir() and not _pull_dir(path):
        raise CorruptObjectError(path, "cached folder is gone from the store")
    seal = path.with_name(path.name + SEAL_SUFFIX)
    try:
        expected = json.loads(seal.read_text(encoding="utf-8"))["files"]
    except (OSError, ValueError, KeyError, TypeError):
        quarantine(path, "it has no readable seal (written by an older release or by a killed run)")
        raise CorruptObjectError(path, "cached folder has no seal; quarantined, it will be recomputed") from None
    actual = {p.relative_to(path).as_posix(): p for p in sorted(path.rglob("*")) if p.is_file()}
    bad = sorted(set(expected) ^ set(actual)) or [rel for rel, p in actual.items() if file_sha256(p) != expected[rel]]
    if bad:
        quarantine(path, f"{bad[0]} does not match its seal")
        raise CorruptObjectError(path / bad[0], "cached file was corrupt (sha256 mismatch); quarantined, "
                                                "run the command again to recompute it")
    _remember(path)


def verify_object(path: str | Path, sha: str) -> None:
    """Check one stored object against its sha256 (quarantined when it does not match)."""
    path = Path(path)
    if _unchanged_since_verified(path):
        return
    if not path.is_file() and not _pull_object(path):
        raise CorruptObjectError(path, "cached object is gone from the store")
    if path.name != f"{sha}.npz" or file_sha256(path) != sha:
        quarantine(path, "its bytes do not match its sha256")
        raise CorruptObjectError(path, "cached object was corrupt (sha256 mismatch); quarantined, "
                                       "run the command again to recompute it")
    _remember(path)


def verify_handles(payload: Any) -> Any:
    """Verify every store handle inside a task result (objects by sha256, store folders by their seal).

    Called for each Prefect result record before it is trusted (``tasks.prefect_env``): a record whose
    object is corrupt, missing or outside the store counts as no record, so its task recomputes."""
    stack = [payload]
    root = cache_root().resolve()
    while stack:
        x = stack.pop()
        if isinstance(x, list):
            stack.extend(x)
            continue
        if not isinstance(x, dict):
            continue
        if isinstance(x.get("sha256"), str) and isinstance(x.get("path"), str) and x.get("kind") != "rejected":
            p = resolve(x["path"])
            if not p.resolve().is_relative_to(root):
                raise CorruptObjectError(p, f"cached result points outside the store {root}")
            if p.suffix == ".npz" and p.parent.parent.resolve() == root / "objects":
                verify_object(p, x["sha256"])
            else:
                verify_dir(p.parent)
        stack.extend(v for v in x.values() if isinstance(v, (dict, list)))
    return payload


_swept: set[str] = set()


def sweep_stale(force: bool = False) -> list[Path]:
    """Remove temporaries that killed runs left in the store (once per process and store root).

    ``.NAME.tmp-PID@HOST-x`` / ``.NAME.old-PID...`` of a dead process on this host go at once; temporaries
    without a process id in their name (``.export-<hash>.<random>.tmp`` of older releases, ``atomic_path``
    files) once older than :data:`STALE_TMP_SECONDS`. Returns what was removed."""
    root = cache_root()
    if str(root) in _swept and not force:
        return []
    _swept.add(str(root))
    host = hashlib.sha1(socket.gethostname().encode()).hexdigest()[:8]
    now = time.time()
    removed: list[Path] = []
    for top in ("objects", "scenes"):
        for sub in sorted((root / top).glob("*")) if (root / top).is_dir() else ():
            for p in sub.iterdir() if sub.is_dir() else ():
                if not p.name.startswith(".") or ".tmp" not in p.name and ".old-" not in p.name:
                    continue
                m = _TMP_PID.match(p.name)
                if m:
                    if m["host"] not in (None, host) or pid_alive(int(m["pid"])):
                        continue
                else:
                    try:
                        if now - p.lstat().st_mtime < STALE_TMP_SECONDS:
                            continue
                    except OSError:
                        continue
                if p.is_dir() and not p.is_symlink():
                    shutil.rmtree(p, ignore_errors=True)
                else:
                    p.unlink(missing_ok=True)
                removed.append(p)
    return removed


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
