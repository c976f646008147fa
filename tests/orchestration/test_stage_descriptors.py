"""Stage descriptors are the one place a stage's dependencies are declared: cache keys,
the sections a task sees and the manifest's versions all follow from them."""

from __future__ import annotations

import copy
import importlib

import pytest

from react3d_core.config import PipelineConfig
from react3d_core.errors import ConfigError
from react3d_core.pipeline import stages
from react3d_core.stage import StageSpec
from tasks.keys import step_key

BASE = PipelineConfig().model_dump(mode="json")
H = {"sha256": "abc", "path": "objects/ab/abc.npz"}

# For a field changed in each section, the steps whose key must change (written out by hand from the
# pipeline's shape: perception -> fusion -> articulation -> dedup/cavity -> assembly -> texture/export -> physics).
EXPECTED = {
    "frames": {"perception", "segmentation", "articulation", "assembly", "export", "physics"},
    "perception": {"perception", "segmentation", "articulation", "assembly", "export", "physics"},
    "fusion": {"segmentation", "articulation", "assembly", "export", "physics"},
    "topk": {"segmentation", "articulation", "assembly", "export", "physics"},
    "clip": {"segmentation", "articulation", "assembly", "export", "physics"},
    "articulation": {"articulation", "assembly", "export", "physics"},
    "limits": {"assembly", "export", "physics"},
    "cavity": {"assembly", "export", "physics"},
    "dedup": {"assembly", "export", "physics"},
    "assembly": {"assembly", "export", "physics"},
    "export": {"export", "physics"},
    "physics": {"physics"},
    "evaluation": set(),  # evaluation is not cached: it never changes a step's key
}


def _keys(config: dict) -> dict[str, str]:
    return {step: step_key(step, {"scene_path": "/x", "handle": H, "config": config}) for step in stages.STEPS}


@pytest.mark.parametrize("section", sorted(EXPECTED))
def test_a_new_field_changes_exactly_its_stage_and_downstream_keys(section: str) -> None:
    assert set(EXPECTED) == set(PipelineConfig.model_fields)  # a new section must be added here, on purpose
    changed = copy.deepcopy(BASE)
    changed[section]["a_field_added_later"] = 1  # what adding a field with a default does to the dumped config
    before, after = _keys(BASE), _keys(changed)
    assert {s for s in stages.STEPS if before[s] != after[s]} == EXPECTED[section]


def test_declaring_a_section_in_a_descriptor_is_all_it_takes(monkeypatch) -> None:  # noqa: ANN001
    """A stage that starts reading 'export' declares it once; its key and everything downstream follows."""
    reg = dict(stages.all_stages())
    reg["cavity"] = StageSpec(**{**reg["cavity"].__dict__, "sections": ("cavity", "export")})
    monkeypatch.setattr(stages, "all_stages", lambda: reg)
    assert "export" in stages.step_sections("assembly")
    changed = copy.deepcopy(BASE)
    changed["export"]["a_field_added_later"] = 1
    before, after = _keys(BASE), _keys(changed)
    assert {s for s in stages.STEPS if before[s] != after[s]} == {"assembly", "export", "physics"}


def test_a_step_cannot_read_a_section_it_does_not_declare() -> None:
    cfg = stages.view(PipelineConfig(), "segmentation")
    assert cfg.fusion.min_cooccurrence == 3 and cfg.perception.backend  # own and upstream sections
    with pytest.raises(ConfigError, match="'cavity'"):
        _ = cfg.cavity
    assert stages.step_config("perception", BASE).keys() == {"frames", "perception"}


def test_every_stage_package_declares_itself_and_the_manifest_versions_follow() -> None:
    reg = stages.all_stages()
    assert list(reg) == ["frames", "perception", "fusion", "articulation", "dedup", "cavity", "assembly", "texture",
                         "export", "physics", "viewer"]
    for spec in reg.values():
        mod = importlib.import_module(spec.module)
        assert mod.STAGE is spec and spec.version == mod.STAGE_VERSION
        assert set(spec.sections) <= set(PipelineConfig.model_fields)
    declared = {sec for s in reg.values() for sec in s.sections}
    assert set(PipelineConfig.model_fields) - declared == {"evaluation"}  # every cached section is keyed
    v = stages.manifest_versions()
    assert v["react3d_core.perception.heuristic"] == importlib.import_module("react3d_core.perception.heuristic").STAGE_VERSION
    assert v["react3d_core.cavity"] == importlib.import_module("react3d_core.cavity").STAGE_VERSION


def test_perception_keys_name_the_model_backend_only_when_it_is_used() -> None:
    """Workers with and without torch share heuristic keys; the key never imports torch, not even to name
    the model backend's version."""
    import subprocess
    import sys

    from tasks.keys import model_backend_version

    assert model_backend_version(BASE) == {}
    models = {**BASE, "perception": {**BASE["perception"], "backend": "models"}}
    assert model_backend_version(models) == {"react3d_models": "3"}
    code = ("import sys; from tasks.perception import perceive_frames; from tasks.keys import step_key, model_backend_version; "
            "from react3d_core.config import PipelineConfig; "
            "step_key('perception', {'config': PipelineConfig().model_dump(mode='json')}); "
            "model_backend_version({'perception': {'backend': 'models'}}); print('torch' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip().splitlines()[-1] == "False", out.stderr[-1500:]
