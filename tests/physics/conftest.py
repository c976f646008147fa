"""Fixtures: the hand-made scenes of ``scenes.py``, each exported once per session (read-only for tests)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.physics.scenes import export


@pytest.fixture(scope="session")
def clean_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The clean scene, exported (read-only for tests)."""
    return export(tmp_path_factory.mktemp("physics") / "clean")


@pytest.fixture(scope="session")
def overlapping_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return export(tmp_path_factory.mktemp("physics") / "overlapping", overlapping=True)


@pytest.fixture(scope="session")
def frontless_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return export(tmp_path_factory.mktemp("physics") / "frontless", door_front=False)


@pytest.fixture(scope="session")
def blocker_out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The clean scene with a held plate in the drawer's way (``scenes.BLOCKER``)."""
    return export(tmp_path_factory.mktemp("physics") / "blocker", blocker=True)
