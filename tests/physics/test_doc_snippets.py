"""The snippets of docs/physics.md "Driving the export in your own code" run as written on an export
(the hand-made door + drawer scene): each opens the door to 0.5 rad with collisions and gravity on. The
PyBullet one runs beside another open connection, as it does in a process that already simulates."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "physics.md"
ENGINE_OF = {"MuJoCo": "mujoco", "PyBullet": "pybullet", "SAPIEN 3": "sapien"}


def snippets() -> dict[str, str]:
    """Engine -> the python block under its bold name in the section."""
    text = DOC.read_text()
    section = text.split("## Driving the export in your own code", 1)[1].split("\n## ", 1)[0]
    out = {}
    for name, engine in ENGINE_OF.items():
        m = re.search(rf"\*\*{re.escape(name)}\*\*.*?```python\n(.*?)```", section, re.S)
        assert m, f"no snippet for {name} in docs/physics.md"
        out[engine] = m.group(1)
    return out


@pytest.mark.parametrize("engine", sorted(ENGINE_OF.values()))
def test_doc_snippet_opens_the_door(clean_out: Path, engine: str) -> None:
    pytest.importorskip(engine)
    code = snippets()[engine].replace('"OUT/', f'"{clean_out.as_posix()}/')
    other = None
    if engine == "pybullet":  # another connection already open in the process (the check's, in the same worker)
        import pybullet

        other = pybullet.connect(pybullet.DIRECT)
        pybullet.loadURDF((clean_out / "export" / "urdf" / "scene.urdf").as_posix(), useFixedBase=True, physicsClientId=other)
    space: dict = {}
    try:
        exec(compile(code, f"docs/physics.md ({engine})", "exec"), space)  # noqa: S102 - our own documentation
    finally:
        if other is not None:
            pybullet.disconnect(other)
    assert space["q"] == pytest.approx(0.5, abs=0.03), engine
