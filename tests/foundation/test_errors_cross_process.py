"""An InputError raised in a spawned worker reaches the parent as the same error (it used to fail to
rebuild there, and a benchmark whose scene folder was incomplete waited for ever)."""

from __future__ import annotations

from pathlib import Path

import pytest

from flows.bench.runner import load_spec, run_isolated
from react3d_core.errors import InputError


def test_input_error_from_a_scene_worker_reaches_the_parent(tmp_path: Path) -> None:
    spec = str(tmp_path / "no-such-scene-*")
    with pytest.raises(InputError) as exc:
        run_isolated(load_spec, spec, tmp_path)
    assert exc.value.path == Path(spec) and "neither a benchmark set file" in exc.value.problem
