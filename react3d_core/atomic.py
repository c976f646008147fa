"""Atomic file writes: write to a temporary sibling and rename, so no half-written output exists."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import secrets
import shutil
import socket
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success rename it onto ``path``.

    The temporary name keeps the suffix so libraries that infer a format from it still work.
    On error the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        # mkstemp creates 0600 files; give the result the permissions a plain open() would have
        with contextlib.suppress(FileNotFoundError):
            os.chmod(tmp_path, 0o666 & ~_umask())
        os.replace(tmp_path, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


# Temporary and displaced folders carry this process's pid and a host tag in their names, so a later
# run can tell a leftover of a dead process (safe to clean) from one that is still being written.
_HOST = hashlib.sha1(socket.gethostname().encode()).hexdigest()[:8]
_LEFTOVER = re.compile(r"^\.(?P<name>.+)\.(?P<kind>tmp|old)-(?P<pid>\d+)(?:@(?P<host>[0-9a-f]{8})-[0-9a-f]+)?$")

OUTPUT_MARKER = ".react3d-output"
"""File written into every folder react3d publishes; only folders holding it (or an output of a release
before the marker, see :func:`is_react3d_output`) may be replaced by a later run."""

# What an output of a release before the marker could hold, and nothing else.
_LEGACY_OUTPUT_ENTRIES = {"scene.json", "meshes", "export", "report.html", "metrics.json"}
_LEGACY_SYNTH_ENTRIES = {"synth_meta.json", "scans", "iphone", "articulate3d", "preview.png"}


def _sibling(path: Path, kind: str) -> Path:
    return path.with_name(f".{path.name}.{kind}-{os.getpid()}@{_HOST}-{secrets.token_hex(4)}")


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this host (a leftover of a dead run may be cleaned)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def read_marker(path: str | Path) -> dict[str, Any] | None:
    """The marker of a react3d output folder, or None when ``path`` holds none (or an unreadable one)."""
    f = Path(path) / OUTPUT_MARKER
    try:
        data = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and "react3d" in data else None


def is_react3d_output(path: str | Path, kind: str | None = None) -> bool:
    """True when ``path`` is a folder react3d wrote: it holds our marker (of ``kind`` when given), or it
    is a conversion output of an older release (only our file names, a manifest with ``objects``)."""
    path = Path(path)
    if path.is_symlink() or not path.is_dir():
        return False
    marker = read_marker(path)
    if marker is not None:
        return kind is None or marker.get("kind") == kind
    names = {p.name for p in path.iterdir()}
    if kind in (None, "synth") and "synth_meta.json" in names and names <= _LEGACY_SYNTH_ENTRIES:
        return True  # a synthetic scan written by ``react3d synth`` before the marker
    if kind not in (None, "scene") or not names <= _LEGACY_OUTPUT_ENTRIES or "scene.json" not in names:
        return False
    try:
        manifest = json.loads((path / "scene.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(manifest, dict) and "objects" in manifest


def clean_leftovers(path: str | Path, marked: bool) -> list[Path]:
    """Remove what killed runs left beside ``path``: our temporary/displaced folders of dead processes.

    Only siblings named ``.NAME.tmp-PID@HOST-x`` / ``.NAME.old-PID[...]`` of this host whose process is
    gone are touched; with ``marked`` they must also be react3d outputs (hold our marker). When a run
    died between moving the old output aside and renaming the new one in, the old one is put back.
    Returns the paths removed or restored."""
    path = Path(path)
    done: list[Path] = []
    try:
        siblings = list(path.parent.iterdir())
    except OSError:
        return done
    for p in sorted(siblings, key=lambda q: q.name):
        m = _LEFTOVER.match(p.name)
        if not m or m["name"] != path.name or p.is_symlink() or not p.is_dir():
            continue
        if m["host"] not in (None, _HOST) or pid_alive(int(m["pid"])):
            continue
        if marked and not is_react3d_output(p):
            continue
        if m["kind"] == "old" and not path.exists() and not path.is_symlink():
            os.replace(p, path)  # the new output never landed: the previous one is the user's result
        else:
            shutil.rmtree(p, ignore_errors=True)
        done.append(p)
    return done


@contextlib.contextmanager
def atomic_dir(path: str | Path, marker: dict[str, Any] | None = None) -> Iterator[Path]:
    """Yield a temporary directory next to ``path``; on success it replaces ``path`` as a whole.

    ``path`` must be a folder or absent: a file or a symbolic link is never replaced. With ``marker``
    the folder is a user-facing output: the marker (JSON, plus the react3d version) is written first,
    so a leftover of a killed run is recognisable as ours and cleaned by the next run.
    """
    from .errors import InputError

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.is_symlink() or (path.exists() and not path.is_dir()):
        raise InputError(path, "exists and is not a folder; react3d replaces only folders it wrote")
    clean_leftovers(path, marked=marker is not None)
    tmp = _sibling(path, "tmp")
    tmp.mkdir()
    try:
        if marker is not None:
            from . import __version__

            (tmp / OUTPUT_MARKER).write_text(json.dumps({"react3d": __version__, **marker}, indent=1), encoding="utf-8")
        yield tmp
        if path.exists():
            old = _sibling(path, "old")
            os.replace(path, old)
            os.replace(tmp, path)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def check_output_dir(out: str | Path, inputs: tuple[str | Path, ...] = (), kind: str = "scene") -> Path:
    """Refuse, before anything runs, an output folder whose replacement could lose data nobody asked to lose.

    Allowed: a new path, an empty folder, or a previous react3d output of the same ``kind``, that is
    neither an input nor holds one. Raises :class:`InputError` (one line: what, where, what to do)
    otherwise; returns the absolute output path."""
    from .errors import InputError

    out = Path(os.path.abspath(out))
    real = out.resolve()
    for inp in inputs:
        src = Path(inp).resolve()
        if real == src:
            raise InputError(out, "is the input; choose a different --out folder (react3d never writes over its input)")
        if src.is_relative_to(real):
            raise InputError(out, f"contains the input {inp}; choose an --out folder outside it")
    if out.is_symlink():
        raise InputError(out, "is a symbolic link; give the folder it points to, or a new folder, as --out")
    if out.exists() and not out.is_dir():
        raise InputError(out, "exists and is a file, not a folder; choose a new --out folder")
    if out.is_dir() and any(out.iterdir()) and not is_react3d_output(out, kind):
        raise InputError(out, f"exists and is not a react3d output (no {OUTPUT_MARKER} file); choose a new or "
                              "empty --out folder (react3d only replaces folders it wrote)")
    probe = out.parent  # the output is renamed into its parent: that (or its nearest existing ancestor) must be writable
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not os.access(probe, os.W_OK | os.X_OK):
        raise InputError(out, "is not writable (read-only folder or file system); choose an --out folder you can write to")
    return out


def write_text(path: str | Path, text: str) -> Path:
    """Atomically write a text file."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_json(path: str | Path, obj: Any, indent: int | None = 2) -> Path:
    """Atomically write JSON (numpy scalars/arrays converted to lists)."""

    def default(o: Any) -> Any:
        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, Path):
            return str(o)
        raise TypeError(f"not JSON serializable: {type(o).__name__}")

    return write_text(path, json.dumps(obj, indent=indent, default=default))


def write_npz(path: str | Path, **arrays: np.ndarray) -> Path:
    """Atomically write a compressed ``.npz`` (never pickled objects)."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return Path(path)


def read_npz(path: str | Path) -> dict[str, np.ndarray]:
    """Read an ``.npz`` written by :func:`write_npz` (pickles refused)."""
    from .errors import InputError
    from .npyio import load_npz

    path = Path(path)
    if not path.is_file():
        raise InputError(path, "file not found")
    try:
        return load_npz(path)
    except Exception as exc:  # noqa: BLE001 - turn any decode failure into one clear line
        raise InputError(path, f"not a readable .npz archive ({exc.__class__.__name__}: {exc})") from None
