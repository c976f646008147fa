"""Conversion processes cap glibc's malloc arenas (tasks/memory.py), unless the user chose otherwise."""

from __future__ import annotations

import subprocess
import sys

import pytest

CODE = "from tasks.memory import limit_malloc_arenas; print(limit_malloc_arenas())"


def _run(env_extra: dict[str, str]) -> str:
    import os

    env = {k: v for k, v in os.environ.items() if k not in ("MALLOC_ARENA_MAX", "REACT3D_MALLOC_ARENAS")}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc only")
def test_arenas_are_capped_unless_the_user_set_them() -> None:
    assert _run({}) == "True"
    assert _run({"MALLOC_ARENA_MAX": "8"}) == "False"  # the user's own setting wins
    assert _run({"REACT3D_MALLOC_ARENAS": "0"}) == "False"  # switched off
    assert _run({"REACT3D_MALLOC_ARENAS": "lots"}) == "False"  # not a number: glibc's default, no traceback
