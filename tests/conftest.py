"""Shared fixtures: synthetic scenes kept on disk between test runs (keyed by the generator's code), and
one Prefect server for every test of a run that needs one (shared across xdist workers)."""

from __future__ import annotations

import ast
import hashlib
import os
import shutil
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SCENES_ENV = "REACT3D_TEST_SCENES"
"""Folder of the generated test scenes kept between runs (default ~/.cache/react3d/test-scenes)."""
STALE_DAYS = 7
"""Scene folders of other generator code unused this long are removed."""


@pytest.fixture(scope="session")
def shared_cache_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder shared by all xdist workers of this run."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    d = root / "react3d-shared"
    d.mkdir(parents=True, exist_ok=True)
    return d


def generator_fingerprint() -> str:
    """The generator's version and a hash of the source of every react3d_core module it imports (found
    by reading the imports, function-level ones too) and of the libraries it calls: a scene built by
    other code is never reused."""
    import re

    core = REPO / "react3d_core"
    version = re.search(r'^GENERATOR_VERSION = "([^"]+)"', (core / "synthetic" / "writer.py").read_text(), re.M)
    todo = sorted((core / "synthetic").glob("*.py"))
    seen: set[Path] = set()
    h = hashlib.sha256()
    while todo:
        f = todo.pop()
        if f in seen or not f.is_file():
            continue
        seen.add(f)
        src = f.read_bytes()
        h.update(f.relative_to(REPO).as_posix().encode() + b"\0" + src)
        pkg = f.parent.relative_to(REPO).parts
        for node in ast.walk(ast.parse(src)):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [(("." * node.level) + (node.module or ""))] + [(("." * node.level) + (node.module + "." if node.module else "") + a.name) for a in node.names]
            for name in names:
                todo.extend(_module_files(name, pkg))
    import importlib.metadata as md

    for lib in ("numpy", "trimesh", "opencv-python-headless", "opencv-python", "scene-synthesizer", "open3d", "scipy"):
        try:
            h.update(f"{lib}={md.version(lib)}".encode())
        except md.PackageNotFoundError:
            pass
    return f"v{version.group(1) if version else 'x'}-{h.hexdigest()[:16]}"


def _module_files(name: str, pkg: tuple[str, ...]) -> list[Path]:
    """Files of ``name`` (absolute or relative to package ``pkg``) if it is part of react3d_core."""
    level = len(name) - len(name.lstrip("."))
    parts = name.lstrip(".").split(".") if name.lstrip(".") else []
    base = list(pkg[: len(pkg) - level + 1]) if level else []
    path = base + parts
    if not path or path[0] != "react3d_core":
        return []
    p = REPO.joinpath(*path)
    parents = [REPO.joinpath(*path[:i], "__init__.py") for i in range(1, len(path))]  # run on import too
    return [f for f in (p.with_suffix(".py"), p / "__init__.py", *parents) if f.is_file()]


def scene_cache_root() -> Path:
    """Where generated scenes are kept for this generator code (one sub-folder per argument set)."""
    base = Path(os.environ.get(SCENES_ENV) or Path.home() / ".cache" / "react3d" / "test-scenes")
    return base / generator_fingerprint()


def _prune_stale(root: Path) -> None:
    """Remove scene folders of other generator code that no run has used for :data:`STALE_DAYS`."""
    cutoff = time.time() - STALE_DAYS * 86400
    for d in root.parent.iterdir() if root.parent.is_dir() else ():
        if d != root and d.is_dir() and d.stat().st_mtime < cutoff and (d / ".react3d-test-scenes").is_file():
            shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="session")
def synthetic_scene(shared_cache_dir: Path) -> Callable[..., Path]:
    """Factory: ``synthetic_scene(source="procedural", seed=0, n_frames=60, **opts) -> scene dir``.

    Each distinct argument set is generated once and kept on disk (``$REACT3D_TEST_SCENES``, default
    ``~/.cache/react3d/test-scenes``) under a folder named by :func:`generator_fingerprint`, so later
    runs reuse it until the generator's code changes. A scene counts only once marked complete (the
    writer builds it aside and renames it; a killed build is made again), under a file lock so parallel
    workers and runs wait for one another instead of generating twice. Treat it as read-only.
    """
    from filelock import FileLock

    root = scene_cache_root()
    root.mkdir(parents=True, exist_ok=True)
    (root / ".react3d-test-scenes").write_text("generated test scenes; safe to delete\n")
    os.utime(root)
    _prune_stale(root)

    def make(source: str = "procedural", seed: int = 0, n_frames: int = 60, **opts: object) -> Path:
        from react3d_core.synthetic import generate_scene

        key = "-".join([source, str(seed), str(n_frames)] + [f"{k}={opts[k]}" for k in sorted(opts)])
        key = "".join(c if c.isalnum() or c in "-=_." else "_" for c in key)
        out = root / key
        with FileLock(str(out) + ".lock"):
            if not (out / ".complete").exists():
                shutil.rmtree(out, ignore_errors=True)  # written, but its build was killed before the mark
                os.environ.setdefault("TMPDIR", str(shared_cache_dir))
                generate_scene(out, source=source, seed=seed, n_frames=n_frames, **opts)  # built aside, renamed
                (out / ".complete").write_text("ok")
        return out

    return make


@dataclass(frozen=True)
class PrefectServer:
    """react3d's local Prefect server of ``home``: what a command finds there when ``PREFECT_HOME=home``."""

    home: Path
    url: str
    template: Path
    """A copy of its database as migrated, before any run (see ``prefect_home_copy``)."""


def _sqlite_copy(src: Path, dst: Path) -> None:
    """Copy a SQLite database that a server may be writing (SQLite's backup API: a consistent copy)."""
    import sqlite3

    tmp = dst.with_name(dst.name + f".{os.getpid()}.tmp")
    a, b = sqlite3.connect(f"file:{src}?mode=ro", uri=True), sqlite3.connect(tmp)
    try:
        a.backup(b)
    finally:
        b.close()
        a.close()
    os.replace(tmp, dst)


@pytest.fixture(scope="session")
def prefect_server(shared_cache_dir: Path) -> Iterator[PrefectServer]:
    """One Prefect server for the whole run: the local server of a session-wide ``PREFECT_HOME``,
    started by the first worker that needs it (commands with that home reuse it as they would a user's),
    stopped by the last one to finish (and by itself a minute after a crashed run)."""
    from filelock import FileLock

    from flows import local_server

    home = shared_cache_dir / "prefect-home"
    template = shared_cache_dir / "prefect-template.db"
    with FileLock(str(template) + ".lock"):  # no worker runs flows before the template is taken
        srv = local_server.connect(home, idle_s=60.0)
        srv.wait_ready(timeout=300)
        if not template.exists():
            _sqlite_copy(home / "prefect.db", template)
    try:
        yield PrefectServer(home, srv.url, template)
    finally:
        srv.release()
        local_server.stop_if_unused(home)


@pytest.fixture(scope="session")
def prefect_home_copy(prefect_server: PrefectServer) -> Callable[[Path], Path]:
    """Factory: ``prefect_home_copy(path) -> path``, a new Prefect home whose database is the run's, as
    migrated and before any run, so a server started there skips the migrations (~10-15 s on 2 cores)
    and its history holds only its own runs."""

    def make(path: Path) -> Path:
        path.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(prefect_server.template, path / "prefect.db")
        return path

    return make
