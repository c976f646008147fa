"""``react3d check``: table and JSON, --strict exit codes, one-line errors; the report's physics section."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from flows.cli import main


def copy(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst)
    return dst


def test_check_writes_json_and_prints_the_table(clean_out: Path, tmp_path: Path, capsys) -> None:  # noqa: ANN001
    pytest.importorskip("mujoco")
    out = copy(clean_out, tmp_path / "out")
    assert main(["check", str(out), "--engines", "mujoco", "--strict"]) == 0
    text = capsys.readouterr().out
    assert "door_joint" in text and "pass" in text and "mujoco" in text
    assert "2/2 joints pass" in text and "cavities 2/2 free, fronts 2/2 blocked" in text
    data = json.loads((out / "physics_check.json").read_text())
    assert [e["engine"] for e in data["engines"]] == ["mujoco"]
    assert {j["object_id"] for j in data["engines"][0]["joints"]} == {"door", "drawer"}


def test_strict_fails_on_an_overlapping_export(overlapping_out: Path, tmp_path: Path, capsys) -> None:  # noqa: ANN001
    pytest.importorskip("mujoco")
    out = copy(overlapping_out, tmp_path / "out")
    target = tmp_path / "elsewhere.json"
    assert main(["check", str(out), "--engines", "mujoco", "--json", str(target), "--no-probes"]) == 0
    assert main(["check", str(out), "--engines", "mujoco", "--json", str(target), "--no-probes", "--strict"]) == 1
    text = capsys.readouterr().out
    assert "FAIL" in text and "world" in text
    data = json.loads(target.read_text())
    assert data["engines"][0]["probes"] == [] and not (out / "physics_check.json").exists()


def test_not_an_output_is_a_one_line_error(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    (tmp_path / "empty").mkdir()
    assert main(["check", str(tmp_path / "empty")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is not a react3d conversion output" in err[0] and str(tmp_path / "empty") in err[0]
    assert main(["check", str(tmp_path / "missing")]) == 2
    assert "not found" in capsys.readouterr().err


def test_unknown_engine_is_refused(clean_out: Path, capsys) -> None:  # noqa: ANN001
    assert main(["check", str(clean_out), "--engines", "mujoco,gazebo"]) == 2
    assert "gazebo" in capsys.readouterr().err


def test_report_shows_the_physics_section(clean_out: Path, tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    from react3d_core.data import InteractiveScene
    from react3d_core.physics import check_output
    from react3d_core.pipeline import record_physics
    from react3d_core.viewer import write_report

    out = copy(clean_out, tmp_path / "out")
    check = check_output(out, engines=("mujoco",))
    record_physics(out / "scene.json", check.model_dump(mode="json"))
    summary = InteractiveScene.load(out / "scene.json").physics
    assert summary["passed"] and summary["engines"]["mujoco"]["passed"] == 2 and summary["file"] == "physics_check.json"
    page = write_report(out / "scene.json", thumbnails=False).read_text()
    assert "Physics check: pass" in page and "<td>door_joint</td>" in page and "2/2 joints pass" in page
    # a check that could not run is said so, and the conversion's manifest still loads
    record_physics(out / "scene.json", None, "RuntimeError: engine exploded")
    page = write_report(out / "scene.json", thumbnails=False).read_text()
    assert "Physics check: FAIL" in page and "engine exploded" in page


def test_convert_flag_chooses_the_engines_or_none() -> None:
    from flows.cli import build_parser
    from flows.commands._runconfig import pipeline_overrides
    from react3d_core.errors import ConfigError

    def parse(*flag: str) -> dict:
        return pipeline_overrides(build_parser().parse_args(["convert", "scene", "--out", "o", *flag]))

    assert parse("--physics", "mujoco,SAPIEN")["physics"] == {"enabled": True, "engines": ["mujoco", "sapien"]}
    assert parse("--physics", "none")["physics"] == {"enabled": False}
    assert "physics" not in parse()
    with pytest.raises(ConfigError, match="gazebo"):
        parse("--physics", "mujoco,gazebo")
