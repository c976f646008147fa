"""``react3d_core.pipeline.convert`` runs the method without Prefect and writes the flow's manifest."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from flows.convert_scene import convert_scene
from react3d_core.data.parts import InteractiveScene

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

ROOT = Path(__file__).resolve().parents[2]
CFG = {"frames": {"stride": 1}, "perception": {"backend": "oracle"}, "export": {"formats": ["urdf"]}}

PIPELINE = """
import json, sys
from react3d_core.pipeline import convert
seen = []
m = convert(sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), progress=lambda s, d, n: seen.append(s))
print(json.dumps({"prefect": "prefect" in sys.modules, "torch": "torch" in sys.modules, "n": len(m.objects),
                  "stages": sorted(set(seen))}))
"""


def _joints(manifest: Path) -> list[dict]:
    m = InteractiveScene.load(manifest)
    return [{"id": o.object_id, "label": o.label, "articulation": o.articulation.model_dump(mode="json"),
             "obb": o.obb.model_dump(mode="json"), "cavity": o.cavity_depth, "mesh": o.part_mesh} for o in m.objects]


def test_pipeline_convert_equals_the_flow_without_importing_prefect(synthetic_scene, tmp_path: Path,  # noqa: ANN001
                                                                     monkeypatch) -> None:
    _same_as_the_flow(synthetic_scene(seed=3, n_frames=16, kind="dresser"), tmp_path, monkeypatch, CFG)


@pytest.mark.slow
def test_the_demo_scene_with_default_settings(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    """The issue's words: the built-in demo scene, the default (weight-free heuristic) config."""
    from react3d_core.synthetic import demo_scene

    _same_as_the_flow(demo_scene(tmp_path / "demo"), tmp_path, monkeypatch, {"export": {"formats": ["urdf"]}})


def _same_as_the_flow(scene: Path, tmp_path: Path, monkeypatch, cfg: dict) -> None:  # noqa: ANN001
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))  # the flow computes, it does not reuse
    out = subprocess.run([sys.executable, "-c", PIPELINE, str(scene), str(tmp_path / "core"), json.dumps(cfg)],
                         cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    info = json.loads(out.stdout.strip().splitlines()[-1])
    assert info == {"prefect": False, "torch": False, "n": info["n"],
                    "stages": ["articulation", "assembly", "export", "perception", "physics", "report", "segmentation"]}
    assert info["n"] > 0

    flow_manifest = Path(convert_scene(str(scene), str(tmp_path / "flow"), cfg))
    core_manifest = tmp_path / "core" / "scene.json"
    assert _joints(core_manifest) == _joints(flow_manifest)
    a, b = InteractiveScene.load(core_manifest), InteractiveScene.load(flow_manifest)
    assert a.config == b.config and a.versions == b.versions
    # the physics check ran in both (URDF only here: MuJoCo, the default engine, has no MJCF and is skipped)
    assert {k: e["status"] for k, e in a.physics["engines"].items()} == {k: e["status"] for k, e in b.physics["engines"].items()}
    assert (tmp_path / "core" / a.input_mesh).resolve() == (tmp_path / "flow" / b.input_mesh).resolve()
    assert (tmp_path / "core" / "export" / "urdf" / "scene.urdf").is_file() and (tmp_path / "core" / "report.html").is_file()
    assert json.loads((tmp_path / "core" / "metrics.json").read_text()) == json.loads((tmp_path / "flow" / "metrics.json").read_text())
