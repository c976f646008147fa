"""One S3-compatible server process (s3rver) per test module, and the environment that points react3d
at a fresh bucket prefix of it."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from deployments.local_cluster import S3Server, s3rver_command


@pytest.fixture(scope="module")
def s3(tmp_path_factory: pytest.TempPathFactory) -> Iterator[S3Server]:
    if s3rver_command() is None:
        pytest.skip("s3rver not installed (bash scripts/setup.sh test)")
    with S3Server(tmp_path_factory.mktemp("s3") / "data") as srv:
        yield srv


@pytest.fixture()
def s3_prefix(s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A prefix of its own on the server, credentials set, a local cache under ``tmp_path``, no store."""
    for k, v in s3.env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("REACT3D_STORE", raising=False)
    monkeypatch.delenv("REACT3D_SCAN_CACHE_GB", raising=False)
    return s3.url(tmp_path.name)
