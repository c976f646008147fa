"""The one pipeline config: every threshold with the paper's default and what it does.

One module per stage package, named after it (``config/cavity.py`` holds the ``cavity`` section read by
``react3d_core/cavity``); this module composes them into :class:`PipelineConfig`.

Load from JSON/YAML-like dicts with ``PipelineConfig.model_validate(d)``; a run records
``config.model_dump(mode="json")`` in its manifest.
"""

from __future__ import annotations

import json
from pathlib import Path

from pydantic import Field, ValidationError

from ..errors import ConfigError
from ._base import StageConfig
from .articulation import ArticulationConfig, LimitConfig
from .assembly import AssemblyConfig
from .cavity import CavityConfig
from .dedup import DedupConfig
from .export import ExportConfig
from .fusion import ClipConfig, FusionConfig, TopKConfig
from .heuristic import FrontRulesConfig, HeuristicConfig
from .metrics import EvaluationConfig
from .models import ModelsConfig
from .perception import OracleNoiseConfig, PerceptionConfig
from .physics import PhysicsConfig
from .scene_io import FrameSelectionConfig


class PipelineConfig(StageConfig):
    """All stages' settings."""

    frames: FrameSelectionConfig = Field(default_factory=FrameSelectionConfig, description="Which frames of a capture are used.")
    perception: PerceptionConfig = Field(default_factory=PerceptionConfig, description="Perception backend and its thresholds.")
    fusion: FusionConfig = Field(default_factory=FusionConfig, description="Multi-view 2D->3D fusion into part proposals.")
    topk: TopKConfig = Field(default_factory=TopKConfig, description="Best views per proposal.")
    clip: ClipConfig = Field(default_factory=ClipConfig, description="Clipping segmented meshes to the movable slab.")
    articulation: ArticulationConfig = Field(default_factory=ArticulationConfig, description="Candidate validation and joint refinement.")
    limits: LimitConfig = Field(default_factory=LimitConfig, description="Motion limits.")
    cavity: CavityConfig = Field(default_factory=CavityConfig, description="Hidden geometry behind movable parts.")
    dedup: DedupConfig = Field(default_factory=DedupConfig, description="Duplicate part removal.")
    assembly: AssemblyConfig = Field(default_factory=AssemblyConfig, description="Carving the background.")
    export: ExportConfig = Field(default_factory=ExportConfig, description="What the exporters write.")
    physics: PhysicsConfig = Field(default_factory=PhysicsConfig, description="The physics check run after the export.")
    evaluation: EvaluationConfig = Field(default_factory=EvaluationConfig, description="Evaluation protocol thresholds.")

    def with_overrides(self, overrides: dict) -> "PipelineConfig":
        """Return a copy with nested overrides, e.g. ``{"perception": {"backend": "oracle"}}``."""
        data = self.model_dump()
        _deep_update(data, overrides)
        try:
            return PipelineConfig.model_validate(data)
        except ValidationError as exc:
            raise ConfigError(f"invalid config override: {validation_summary(exc)}") from None

    @classmethod
    def from_file(cls, path: str | Path) -> "PipelineConfig":
        """Read a JSON config file (partial: missing keys keep their defaults)."""
        path = Path(path)
        try:
            data = json.loads(path.read_text())
        except FileNotFoundError:
            raise ConfigError(f"{path}: config file not found") from None
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{path}: not valid JSON ({exc})") from None
        try:
            return cls.model_validate(data)
        except ValidationError as exc:
            raise ConfigError(f"{path}: invalid config: {validation_summary(exc)}") from None


def validation_summary(exc: ValidationError) -> str:
    """Every problem of a validation error on one line, as ``section.field: what is wrong`` (the CLI shows one
    line; pydantic's own text spreads each problem over three and ends in a URL). Inputs are not echoed."""
    return "; ".join(f"{'.'.join(str(p) for p in e['loc']) or 'config'}: {e['msg']}" for e in exc.errors())


def _deep_update(base: dict, upd: dict) -> None:
    for k, v in upd.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _deep_update(base[k], v)
        else:
            base[k] = v


__all__ = [
    "ArticulationConfig",
    "AssemblyConfig",
    "CavityConfig",
    "ClipConfig",
    "DedupConfig",
    "EvaluationConfig",
    "ExportConfig",
    "FrameSelectionConfig",
    "FrontRulesConfig",
    "FusionConfig",
    "HeuristicConfig",
    "LimitConfig",
    "ModelsConfig",
    "OracleNoiseConfig",
    "PerceptionConfig",
    "PhysicsConfig",
    "PipelineConfig",
    "StageConfig",
    "TopKConfig",
]
