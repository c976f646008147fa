"""Prefect test set-up: a private object store and result storage per session, the run's shared Prefect
server (``prefect_server``) as this process's API, quiet settings."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest


@pytest.fixture(scope="session", autouse=True)
def prefect_env(tmp_path_factory: pytest.TempPathFactory, prefect_server) -> Iterator[Path]:  # noqa: ANN001
    home = tmp_path_factory.mktemp("prefect-home")
    os.environ["REACT3D_CACHE"] = str(home / "react3d-cache")
    os.environ["PREFECT_LOCAL_STORAGE_PATH"] = str(home / "storage")
    os.environ["PREFECT_API_URL"] = prefect_server.url
    from tasks import prefect_env as pe

    pe.configure()
    import prefect.context

    prefect.context.refresh_global_settings_context()  # Prefect may have read its settings at collection
    try:
        yield home
    finally:
        _drain()
        del os.environ["PREFECT_API_URL"]
        prefect.context.refresh_global_settings_context()


def _drain() -> None:
    """Send the logs and events still queued in this process before the server may stop."""
    from prefect.events.worker import EventsWorker
    from prefect.logging.handlers import APILogWorker

    try:
        APILogWorker.drain_all(timeout=30)
    except RuntimeError:
        pass
    EventsWorker.drain_all(timeout=30)
