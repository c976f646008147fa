"""Shared fixtures: synthetic scenes generated once per test session (shared across xdist workers)."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def shared_cache_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder shared by all xdist workers of this run."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    d = root / "react3d-shared"
    d.mkdir(parents=True, exist_ok=True)
    return d


@pytest.fixture(scope="session")
def synthetic_scene(shared_cache_dir: Path) -> Callable[..., Path]:
    """Factory: ``synthetic_scene(source="procedural", seed=0, n_frames=60, **opts) -> scene dir``.

    Each distinct argument set is generated once per test run, under a file lock so parallel
    workers wait for one another instead of generating twice. Treat the returned folder as read-only.
    """
    from filelock import FileLock

    def make(source: str = "procedural", seed: int = 0, n_frames: int = 60, **opts: object) -> Path:
        from react3d_core.synthetic import generate_scene

        key = "-".join([source, str(seed), str(n_frames)] + [f"{k}={opts[k]}" for k in sorted(opts)])
        key = "".join(c if c.isalnum() or c in "-=_." else "_" for c in key)
        out = shared_cache_dir / "scenes" / key
        with FileLock(str(out) + ".lock"):
            if not (out / ".complete").exists():
                os.environ.setdefault("TMPDIR", str(shared_cache_dir))
                generate_scene(out, source=source, seed=seed, n_frames=n_frames, **opts)
                (out / ".complete").write_text("ok")
        return out

    return make
