"""The check at the end of a conversion: recorded in scene.json and report.html, switchable, and a check
that cannot run never fails the conversion."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from react3d_core.pipeline import convert

CFG = {"perception": {"backend": "oracle"}, "frames": {"stride": 2}, "export": {"formats": ["urdf", "mjcf"]}}


@pytest.fixture(scope="module")
def scene(synthetic_scene) -> Path:  # noqa: ANN001
    return synthetic_scene(seed=3, n_frames=16, kind="dresser")


@pytest.mark.slow
def test_convert_records_the_check(scene: Path, tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    m = convert(scene, tmp_path / "out", CFG)
    assert m.objects and m.physics is not None and m.physics["file"] == "physics_check.json"
    mj = m.physics["engines"]["mujoco"]
    assert mj["status"] == "ok" and mj["joints"] == len(m.objects) and "physics" in m.timings
    full = json.loads((tmp_path / "out" / "physics_check.json").read_text())
    assert {j["object_id"] for j in full["engines"][0]["joints"]} == {o.object_id for o in m.objects}
    assert "Physics check:" in (tmp_path / "out" / "report.html").read_text()


@pytest.mark.slow
def test_switched_off_and_failing_checks_leave_the_conversion_alone(scene: Path, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    m = convert(scene, tmp_path / "off", {**CFG, "physics": {"enabled": False}})
    assert m.physics is None and not (tmp_path / "off" / "physics_check.json").exists()
    import react3d_core.physics as physics

    def broken(*a, **k):  # noqa: ANN002, ANN003, ANN202
        raise RuntimeError("simulator crashed")

    monkeypatch.setattr(physics, "check_output", broken)
    m = convert(scene, tmp_path / "broken", CFG)
    assert m.objects and m.physics == {"passed": False, "error": "RuntimeError: simulator crashed"}
    assert "simulator crashed" in (tmp_path / "broken" / "report.html").read_text()
