"""Prefect test set-up: a private PREFECT_HOME and object store per session, Prefect's test harness
(a temporary SQLite server), quiet settings."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest


@pytest.fixture(scope="session", autouse=True)
def prefect_env(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    home = tmp_path_factory.mktemp("prefect-home")
    os.environ["PREFECT_HOME"] = str(home)
    os.environ["REACT3D_CACHE"] = str(home / "react3d-cache")
    os.environ["PREFECT_LOCAL_STORAGE_PATH"] = str(home / "storage")
    from tasks import prefect_env as pe

    pe.configure()
    from prefect.testing.utilities import prefect_test_harness

    with prefect_test_harness(server_startup_timeout=180):
        yield home
