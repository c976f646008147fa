"""Pruning the store itself (a local folder, a shared mount or an ``s3://`` prefix): ``react3d cache clean --store``.

What keeps an entry of the store alive is a Prefect result record: a cached task's record holds the
handles of its objects (``objects/<aa>/<sha256>.npz``) and store folders (``scenes/<aa>/<stage>-<hash>/``
with ``<stage>-<hash>.seal.json`` beside it); nothing else can find them (cache keys lead to records,
records to handles). So a clean

1. drops the records of react3d's tasks (named ``<step>-<40 hex>``) not written for ``older_than`` days
   (none without ``older_than``);
2. drops every object and store folder that no remaining record mentions, unless it was written within
   ``grace`` seconds: a running conversion writes an object before the record that names it.

Only entries in the store's own layout are ever touched (names as react3d makes them, under
``objects/``, ``scenes/`` and the records folder); anything else found there is left and counted.
Everything goes through fsspec, so a local folder and a bucket are pruned by the same code.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from react3d_core.errors import InputError

from . import storage
from .store import SEAL_SUFFIX

OBJECT_RE = re.compile(r"^objects/(?P<aa>[0-9a-f]{2})/(?P<sha>[0-9a-f]{64})\.npz$")
FOLDER_RE = re.compile(r"^scenes/(?P<aa>[0-9a-f]{2})/(?P<name>[a-z][a-z0-9_]*-(?P<hex>[0-9a-f]{32}))(?P<rest>/.+|\.seal\.json)$")
RECORD_RE = re.compile(r"^[a-z][a-z0-9_-]*-[0-9a-f]{40}$")
"""Names of react3d's task result records (``tasks.keys.step_key``); other records are never removed."""
REF_RE = re.compile(r"(objects/[0-9a-f]{2}/[0-9a-f]{64}\.npz|scenes/[0-9a-f]{2}/[a-z][a-z0-9_]*-[0-9a-f]{32})(?=[/\"\\.]|$)")
"""What a record mentions, found in its raw text (a record's result is JSON inside JSON: any mention counts)."""

DEFAULT_GRACE_S = 3600.0
"""Unreferenced entries written this recently are kept (an in-flight task's object before its record)."""


@dataclass(frozen=True)
class Entry:
    """One thing a clean may remove: a record, an object, or a store folder with its seal (``rel`` ends in /)."""

    rel: str
    """Path relative to the store root (records: relative to the records folder, prefixed ``records/``)."""
    kind: str
    size: int
    mtime: float
    paths: tuple[str, ...]
    """The filesystem paths to delete, the seal of a folder first."""


@dataclass
class Plan:
    """What a clean of the store removes, and what it saw."""

    store: str
    records_at: str
    remove: list[Entry]
    records_kept: int
    kept: int
    """Entries of the layout kept (referenced, or too recent)."""
    foreign: int
    """Files under the store's folders that are not in react3d's layout (never removed)."""


def store_location() -> tuple[str, str]:
    """The store (URL or local folder) and the folder (URL) of its Prefect result records."""
    st = storage.settings()
    root = storage.remote_root()
    if root is not None:
        return root, f"{root}/{storage.RESULTS_DIR}"
    local = storage.cache_root()
    records = os.environ.get("PREFECT_LOCAL_STORAGE_PATH")
    if not records:
        home = Path(os.environ.get("PREFECT_HOME", Path.home() / ".prefect"))
        records = str(storage.local_path(st.store) / storage.RESULTS_DIR) if st.store else str(home / "storage")
    return str(local), records


def _mtime(info: dict[str, Any]) -> float:
    for k in ("mtime", "LastModified", "last_modified", "updated"):
        v = info.get(k)
        if isinstance(v, datetime):
            return v.timestamp()
        if isinstance(v, (int, float)):
            return float(v)
    return time.time()  # unknown age: counts as new, so it is never removed by age


def plan_clean(older_than_days: float | None = None, grace_s: float = DEFAULT_GRACE_S,
               now: float | None = None) -> Plan:
    """What ``cache clean --store`` removes now (see the module docstring); removes nothing itself."""
    now = time.time() if now is None else now
    store, records_at = store_location()
    fs, root = storage.filesystem(store)
    root = root.rstrip("/")
    _, rec_root = storage.filesystem(records_at)
    rec_root = rec_root.rstrip("/")
    cutoff = None if older_than_days is None else now - older_than_days * 86400

    remove: list[Entry] = []
    records = storage.find_files(records_at)
    live: list[str] = []
    for rel, info in sorted(records.items()):
        if cutoff is not None and RECORD_RE.match(rel) and _mtime(info) < cutoff:
            remove.append(Entry(f"records/{rel}", "record", int(info.get("size", 0)), _mtime(info), (f"{rec_root}/{rel}",)))
        else:
            live.append(f"{rec_root}/{rel}")
    referenced = _references(fs, live)

    files = {f"{top}/{rel}": info for top in ("objects", "scenes") for rel, info in storage.find_files(f"{store}/{top}").items()}
    if rec_root.startswith(root + "/"):  # records kept inside the store are not store entries
        inner = rec_root[len(root) + 1:] + "/"
        files = {k: v for k, v in files.items() if not k.startswith(inner)}
    folders: dict[str, list[tuple[str, dict[str, Any]]]] = {}
    kept = foreign = 0
    for rel, info in sorted(files.items()):
        m = OBJECT_RE.match(rel)
        if m and m["aa"] == m["sha"][:2]:
            if rel in referenced or now - _mtime(info) < grace_s:
                kept += 1
            else:
                remove.append(Entry(rel, "object", int(info.get("size", 0)), _mtime(info), (f"{root}/{rel}",)))
            continue
        m = FOLDER_RE.match(rel)
        if m and m["aa"] == m["hex"][:2]:
            folders.setdefault(f"scenes/{m['aa']}/{m['name']}", []).append((rel, info))
        else:
            foreign += 1
    for folder, members in sorted(folders.items()):
        newest = max(_mtime(i) for _, i in members)
        if folder in referenced or now - newest < grace_s:
            kept += 1
            continue
        seal = [f"{root}/{r}" for r, _ in members if r.endswith(SEAL_SUFFIX) and r.count("/") == 2]
        rest = [f"{root}/{r}" for r, _ in members if f"{root}/{r}" not in seal]
        remove.append(Entry(f"{folder}/", "folder", sum(int(i.get("size", 0)) for _, i in members), newest,
                            tuple(seal + rest)))  # the seal first: a reader never trusts a half-removed folder
    return Plan(store, records_at, remove, len(live), kept, foreign)


def _references(fs: Any, record_paths: Iterable[str]) -> set[str]:
    """Every object and store folder the records mention."""
    paths = list(record_paths)
    refs: set[str] = set()
    for i in range(0, len(paths), 256):  # one concurrent batch of reads per chunk on a bucket
        chunk = paths[i:i + 256]
        try:
            texts = fs.cat(chunk, on_error="return")
        except TypeError:
            texts = {p: fs.cat_file(p) for p in chunk}
        for p, data in texts.items():
            if isinstance(data, Exception):
                if isinstance(data, FileNotFoundError):  # removed since the listing: references nothing
                    continue
                raise InputError(p, f"cannot read this result record ({type(data).__name__}: {data}); "
                                    "nothing removed: its references are unknown")
            refs.update(REF_RE.findall(data.decode("utf-8", errors="replace")))
    return refs


def apply(plan: Plan) -> int:
    """Remove what ``plan`` lists: records first (so none names a removed object), then folders (seal
    first), then objects. Refuses when no record is left while objects would go (a records folder at
    another place than the workers' would make every object look unreferenced). Returns entries removed."""
    if plan.records_kept == 0 and any(e.kind != "record" for e in plan.remove):
        raise InputError(plan.records_at, "holds no result records, so nothing references the store's objects; "
                                          "nothing removed (check PREFECT_LOCAL_STORAGE_PATH / REACT3D_STORE, or "
                                          "empty a local cache with `react3d cache clean` without --store)")
    fs, _ = storage.filesystem(plan.store)
    order = {"record": 0, "folder": 1, "object": 2}
    n = 0
    for e in sorted(plan.remove, key=lambda e: order[e.kind]):
        for p in e.paths:
            try:
                fs.rm_file(p)
            except FileNotFoundError:
                pass
        if e.kind == "folder" and not storage.is_remote(plan.store):
            _remove_empty_dirs(Path(plan.store) / e.rel)
        n += 1
    return n


def _remove_empty_dirs(folder: Path) -> None:
    """Remove a local store folder's sub-folders left empty by its files' removal, then the folder itself."""
    for d, _, _ in sorted(os.walk(folder), key=lambda t: -len(t[0])):
        try:
            os.rmdir(d)
        except OSError:
            pass
