"""The ``perception.models`` section (react3d_core/config/models.py) without torch: its defaults, the keys
that moved into it, its documentation table, and the import direction of the react3d_models package."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from react3d_core.config import ModelsConfig, PipelineConfig
from react3d_core.config.models import MOVED_TO_MODELS
from react3d_core.config.reference import markdown_table, section
from react3d_core.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]

# the defaults these settings had before the section existed: the flat PerceptionConfig fields and the
# backend's own option model (hand-written: a changed default must be a deliberate edit here)
OLD_DEFAULTS = {
    "detector_model": "IDEA-Research/grounding-dino-tiny", "sam_model": "facebook/sam-vit-huge",
    "tagger_model": "xinyu1205/recognize-anything-plus-model", "tag_filter_endpoint": None,
    "tag_filter_model": "llava-hf/llava-1.5-7b-hf", "articulation_endpoint": None, "batch_size": 8, "device": "auto",
    "box_threshold": 0.3, "text_threshold": 0.25,
    "dtype": "auto", "clip_model": "openai/clip-vit-base-patch32", "tag_top_k": 8, "tag_min_prob": 0.03,
    "llm_timeout_s": 60.0, "llm_retries": 3, "llm_backoff_s": 1.0, "llm_max_new_tokens": 256, "max_detections": 100,
    "gpu_preprocess": True, "articulation_timeout_s": 300.0, "articulation_min_score": 0.5,
    # keyword defaults of the adapters that no config could set before
    "nms_iou": 0.8, "articulation_retries": 2, "articulation_backoff_s": 1.0, "llm_endpoint_max_tokens": 512,
}


def test_section_keeps_the_old_defaults() -> None:
    m = PipelineConfig().perception.models
    assert {k: getattr(m, k) for k in OLD_DEFAULTS} == OLD_DEFAULTS
    assert set(type(m).model_fields) == set(OLD_DEFAULTS) | {"tag_vocabulary"}
    assert len(m.tag_vocabulary) == 33 and {"cabinet", "drawer", "door", "wall"} <= set(m.tag_vocabulary)


@pytest.mark.parametrize("key", MOVED_TO_MODELS)
def test_a_flat_key_names_its_new_place(key: str, tmp_path: Path) -> None:
    value = "https://api.example.com/v1?api_key=sk-secret-1" if key.endswith("endpoint") else 0.5
    with pytest.raises(ConfigError) as e:
        PipelineConfig().with_overrides({"perception": {key: value}})
    msg = str(e.value)
    assert f"perception.{key} is now perception.models.{key}" in msg and "\n" not in msg and "sk-secret-1" not in msg
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"perception": {"backend": "models", key: value}}))
    with pytest.raises(ConfigError, match=f"perception.models.{key}"):
        PipelineConfig.from_file(path)


def test_the_cli_says_where_an_old_key_went_in_one_line(tmp_path: Path) -> None:
    """``react3d convert --config old.json`` stops before anything runs, with one line naming the new key."""
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"perception": {"backend": "models", "device": "cuda", "detector_model": "x"}}))
    p = subprocess.run([sys.executable, "-m", "flows.cli", "convert", str(tmp_path / "scene"), "--out", str(tmp_path / "out"),
                        "--config", str(path)], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and "perception.device is now perception.models.device" in lines[0]
    assert "perception.detector_model is now perception.models.detector_model" in lines[0]
    assert not (tmp_path / "out").exists()


def test_bad_value_reaches_the_cli_as_one_line_naming_the_field(tmp_path: Path) -> None:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"perception": {"models": {"dtype": "fp8", "max_detections": 0}}}))
    p = subprocess.run([sys.executable, "-m", "flows.cli", "convert", str(tmp_path / "scene"), "--out", str(tmp_path / "out"),
                        "--config", str(path)], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 2
    line = p.stderr.strip().splitlines()[0]
    assert "perception.models.dtype: Input should be 'auto', 'fp32', 'fp16' or 'bf16'" in line
    assert "perception.models.max_detections: Input should be greater than or equal to 1" in line


def test_docs_table_is_generated_from_the_section() -> None:
    """docs/perception_models.md carries the table ``python3 -m react3d_core.config.reference perception.models``
    prints; regenerate it there when a field changes."""
    assert section("perception.models") is ModelsConfig
    doc = (ROOT / "docs" / "perception_models.md").read_text()
    assert markdown_table(ModelsConfig) in doc
    example = doc.split("<!-- example-config -->", 2)[1]
    cfg = json.loads(example.split("```json", 1)[1].split("```", 1)[0])
    m = PipelineConfig.model_validate(cfg).perception.models
    assert m.dtype == "bf16" and m.tag_vocabulary != ModelsConfig().tag_vocabulary


def test_deployment_configs_validate() -> None:
    spec = yaml.safe_load((ROOT / "deployments" / "prefect.yaml").read_text())
    configs = [d["parameters"]["config"] for d in spec["deployments"] if "config" in d.get("parameters", {})]
    assert configs
    for c in configs:
        PipelineConfig().with_overrides(c)


def _imports(path: Path) -> set[str]:
    """Every module an ``import``/``from ... import`` in the file names, at any depth (lazy imports too)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.add(node.module)
    return out


def test_the_model_package_imports_nothing_from_tasks_or_flows() -> None:
    files = sorted((ROOT / "react3d_models").rglob("*.py"))
    assert len(files) >= 10
    bad = {f.name: sorted(m for m in _imports(f) if m.split(".")[0] in ("tasks", "flows")) for f in files}
    assert {k: v for k, v in bad.items() if v} == {}
    assert any("react3d_core" in m for f in files for m in _imports(f))  # the scan does see imports


def test_importing_the_model_package_loads_neither_torch_nor_tasks() -> None:
    """In a fresh interpreter: the package and its version load without torch (cache keys name the version);
    its backend module, when torch is here, pulls in nothing from tasks/ or flows/."""
    code = ("import sys, json; import react3d_models, react3d_models.version; a = 'torch' in sys.modules\n"
            "try:\n    import torch, transformers  # noqa\n    from react3d_models import make_model_perception  # noqa\n"
            "    full = True\nexcept ImportError:\n    full = False\n"
            "print(json.dumps({'torch_at_import': a, 'full': full, "
            "'ours': sorted(m for m in sys.modules if m.split('.')[0] in ('tasks', 'flows'))}))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["torch_at_import"] is False and res["ours"] == []


def test_models_backend_without_torch_is_one_config_error() -> None:
    """The core factory imports react3d_models only when the config names it; without torch that is one line
    saying what to install."""
    code = ("import sys; sys.modules['torch'] = None\n"
            "from react3d_core.config import PerceptionConfig\n"
            "from react3d_core.errors import ConfigError\n"
            "from react3d_core.perception.factory import plugin_builder\n"
            "try:\n    plugin_builder('models')\nexcept ConfigError as e:\n    print('ERR', e)\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    line = out.stdout.strip().splitlines()[-1]
    assert line.startswith("ERR perception.backend='models' needs the react3d_models package"), out.stderr[-2000:]
    assert "pip install -e '.[models]'" in line and "torch" in line
