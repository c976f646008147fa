"""Input scans at a URL (``s3://bucket/scans/<scene>``): streamed into this machine's scan cache, bounded in size,
checked, evicted least recently used.

The pipeline reads local files, so a remote scan is downloaded whole before its conversion starts, into
``<cache>/scans/<key>/<scene>`` (``key``: the URL's sha256). Beside it, ``<key>.json`` records every file's
size, the remote ETag and the sha256 of what was downloaded; its modification time is the entry's last
use. A later conversion of the same URL reuses the copy when the remote listing (names, sizes, ETags) is
unchanged and the local files still have their recorded sizes; anything else downloads it again. Every
downloaded file is checked against the remote size, and against the ETag when that is a plain MD5 (a
single-part upload); a file that does not match is read once more if the listing changed meanwhile, and
otherwise refused with one line naming it (damaged in the store). The content keys do not change: they hash the scan's files (``fingerprint_scene``),
never its location.

Bounded: ``REACT3D_SCAN_CACHE_GB`` (default 20). Before a download, the least recently used entries are
evicted until the new scan fits; an entry a conversion is reading (a shared ``flock`` on its record,
held for the whole conversion) is never evicted. A scan larger than the bound, or one that cannot fit
beside the scans in use, or on a disk without that much free space, is refused with one line before
its download starts.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from react3d_core.errors import InputError

from . import storage

DEFAULT_GB = 20.0


def bound_bytes() -> int:
    """The scan cache's size bound (``REACT3D_SCAN_CACHE_GB``)."""
    raw = os.environ.get("REACT3D_SCAN_CACHE_GB", str(DEFAULT_GB))
    try:
        gb = float(raw)
    except ValueError:
        raise InputError(None, f"REACT3D_SCAN_CACHE_GB={raw!r} is not a number of gigabytes") from None
    return int(gb * 1e9)


def cache_dir() -> Path:
    return storage.cache_root() / "scans"


def _listing(url: str) -> dict[str, dict[str, Any]]:
    """The scan's files (hidden ones skipped, as the scene fingerprint skips them): size and ETag by path."""
    files = {rel: {"size": int(info.get("size", 0)), "etag": str(info.get("ETag", "")).strip('"')}
             for rel, info in storage.find_files(url).items()
             if rel and not any(p.startswith(".") for p in rel.split("/"))}
    if not files:
        raise InputError(url, "no scan files there (an empty or missing prefix)")
    return files


def _md5_etag(etag: str) -> bool:
    return len(etag) == 32 and all(c in "0123456789abcdef" for c in etag)


@contextmanager
def local_scene(url: str) -> Iterator[Path]:
    """A verified local copy of the remote scan ``url``, kept from eviction while the ``with`` block runs."""
    url = url.rstrip("/")
    listing = _listing(url)
    key = hashlib.sha256(url.encode()).hexdigest()[:24]
    root = cache_dir()
    root.mkdir(parents=True, exist_ok=True)
    record = root / f"{key}.json"
    name = url.rsplit("/", 1)[-1] or "scan"
    dest = root / key / name
    with open(root / f"{key}.lock", "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_SH)  # conversions share it; eviction and downloads need it alone
        if not _usable(record, dest, listing):
            fcntl.flock(lock, fcntl.LOCK_EX)  # waits for this scan's running conversions: one downloader
            if not _usable(record, dest, listing):
                try:
                    _download(url, listing, key, record, dest)
                except ScanMismatchError:
                    # an object that changed while it was read is read again, once; one damaged in the
                    # store lists the same again and is refused with its line
                    again = _listing(url)
                    if again == listing:
                        raise
                    _download(url, again, key, record, dest)
            fcntl.flock(lock, fcntl.LOCK_SH)
        os.utime(record)  # last use
        yield dest


def _usable(record: Path, dest: Path, listing: dict[str, dict[str, Any]]) -> bool:
    try:
        rec = json.loads(record.read_text(encoding="utf-8"))
        files = rec["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return False
    if {k: {"size": v["size"], "etag": v["etag"]} for k, v in files.items()} != listing:
        return False  # changed on the remote
    try:
        return all((dest / rel).stat().st_size == meta["size"] for rel, meta in files.items())
    except OSError:
        return False


def _download(url: str, listing: dict[str, dict[str, Any]], key: str, record: Path, dest: Path) -> None:
    need = sum(f["size"] for f in listing.values())
    bound = bound_bytes()
    if need > bound:
        raise InputError(url, f"the scan is {need / 1e9:.2f} GB, more than the scan cache holds "
                              f"(REACT3D_SCAN_CACHE_GB={bound / 1e9:g}); raise it")
    record.unlink(missing_ok=True)
    shutil.rmtree(dest.parent, ignore_errors=True)
    evict(need, keep=key)
    check_free_space(cache_dir(), need, url)
    fs, path = storage.filesystem(url)
    path = path.rstrip("/")
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{dest.name}.", suffix=".tmp", dir=dest.parent))
    try:
        rels = sorted(listing)
        targets = [tmp / r for r in rels]
        for t in targets:
            t.parent.mkdir(parents=True, exist_ok=True)
        fs.get([f"{path}/{r}" for r in rels], [str(t) for t in targets])
        files = {}
        for rel, t in zip(rels, targets):
            size, sha, md5 = _digest(t)
            want = listing[rel]
            if size != want["size"]:
                raise ScanMismatchError(f"{url}/{rel}", f"downloaded {size} bytes, the store lists {want['size']}: "
                                                        "a truncated or changing object; run again")
            if _md5_etag(want["etag"]) and md5 != want["etag"]:
                raise ScanMismatchError(f"{url}/{rel}", f"the downloaded bytes do not match the store's ETag (MD5 "
                                                        f"{md5[:12]}..., ETag {want['etag'][:12]}...): the object is "
                                                        "damaged in the store (truncated?) or changed while read; "
                                                        "upload it again")
            files[rel] = {**want, "sha256": sha}
        os.replace(tmp, dest)
        record.write_text(json.dumps({"url": url, "files": files, "bytes": need}, indent=0), encoding="utf-8")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


class ScanMismatchError(InputError):
    """A downloaded scan file that does not match the store's listing (size, or MD5 ETag)."""


def check_free_space(where: Path, need: int, url: str) -> None:
    """Refuse a download the local disk cannot hold, before it starts (one line)."""
    free = shutil.disk_usage(where).free
    if need > free:
        raise InputError(where, f"the scan {url} is {need / 1e9:.2f} GB and this disk has {free / 1e9:.2f} GB "
                                "free; free space, or set REACT3D_CACHE to a larger disk")


def _digest(path: Path) -> tuple[int, str, str]:
    sha, md5, n = hashlib.sha256(), hashlib.md5(usedforsecurity=False), 0
    with open(path, "rb") as fh:
        while block := fh.read(1 << 20):
            sha.update(block)
            md5.update(block)
            n += len(block)
    return n, sha.hexdigest(), md5.hexdigest()


def entries() -> list[tuple[str, int, float]]:
    """Cached scans as (key, bytes, last use), least recently used first."""
    out = []
    for rec in cache_dir().glob("*.json") if cache_dir().is_dir() else ():
        try:
            n = int(json.loads(rec.read_text(encoding="utf-8"))["bytes"])
            out.append((rec.stem, n, rec.stat().st_mtime))
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return sorted(out, key=lambda e: e[2])


def evict(need: int, keep: str | None = None) -> list[str]:
    """Remove least recently used scans until ``need`` more bytes fit in the bound; the evicted keys.

    A scan a conversion holds (its shared lock) is skipped; if the rest cannot make room, one line says so."""
    bound = bound_bytes()
    cached = [e for e in entries() if e[0] != keep]
    used = sum(n for _, n, _ in cached)
    evicted = []
    for key, n, _ in cached:
        if used + need <= bound:
            break
        with open(cache_dir() / f"{key}.lock", "a+") as lock:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                continue  # a conversion is reading it
            (cache_dir() / f"{key}.json").unlink(missing_ok=True)
            shutil.rmtree(cache_dir() / key, ignore_errors=True)
        used -= n
        evicted.append(key)
    if used + need > bound:
        raise InputError(cache_dir(), f"the scan cache cannot fit {need / 1e9:.2f} GB more: "
                                      f"{used / 1e9:.2f} GB of {bound / 1e9:g} GB are scans being converted; "
                                      "raise REACT3D_SCAN_CACHE_GB or convert fewer scenes at once")
    return evicted
