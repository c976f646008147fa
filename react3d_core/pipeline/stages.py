"""Everything derived from the stage descriptors (``STAGE`` in each stage package).

A *step* is one unit of work of the pipeline (one Prefect task type): it runs one or more stages.
Its identity (:func:`key_material`) is the versions and declared config sections of its stages and
of every stage upstream of them, so a config field of one stage changes exactly that stage's key and
the keys downstream of it. :class:`ConfigView` hands a step only those sections: reading any other
is an error, so an undeclared dependency cannot hide behind a stale cache hit.
"""

from __future__ import annotations

import importlib
from functools import cache
from typing import Any

from ..config import PipelineConfig
from ..errors import ConfigError
from ..stage import StageSpec

# Stage packages in pipeline order; each declares ``STAGE`` (react3d_core/stage.py).
STAGE_PACKAGES = ("react3d_core.scene_io", "react3d_core.perception", "react3d_core.fusion", "react3d_core.articulation",
                  "react3d_core.dedup", "react3d_core.cavity", "react3d_core.assembly", "react3d_core.texture",
                  "react3d_core.export", "react3d_core.physics", "react3d_core.viewer")

# Steps of a conversion and the stages each runs (perception per frame batch, articulation per part).
STEPS: dict[str, tuple[str, ...]] = {
    "perception": ("perception",),
    "segmentation": ("fusion",),
    "articulation": ("articulation",),
    "assembly": ("dedup", "cavity", "assembly"),
    "export": ("texture", "export"),
    "physics": ("physics",),
}


@cache
def all_stages() -> dict[str, StageSpec]:
    """``{stage name: StageSpec}`` in pipeline order, read from the stage packages."""
    out: dict[str, StageSpec] = {}
    for mod in STAGE_PACKAGES:
        spec = importlib.import_module(mod).STAGE
        missing = [u for u in spec.upstream if u not in out]
        if missing:
            raise RuntimeError(f"{mod}: upstream stage(s) {missing} are not declared before it in STAGE_PACKAGES")
        out[spec.name] = spec
    return out


def closure(stages: tuple[str, ...]) -> list[StageSpec]:
    """The named stages and every stage upstream of them, in pipeline order."""
    reg = all_stages()
    seen: set[str] = set()
    todo = list(stages)
    while todo:
        name = todo.pop()
        if name not in reg:
            raise KeyError(f"unknown stage {name!r} (known: {', '.join(reg)})")
        if name not in seen:
            seen.add(name)
            todo.extend(reg[name].upstream)
    return [s for n, s in reg.items() if n in seen]


def step_stages(step: str) -> tuple[str, ...]:
    try:
        return STEPS[step]
    except KeyError:
        raise KeyError(f"unknown step {step!r} (known: {', '.join(STEPS)})") from None


def step_sections(step: str) -> tuple[str, ...]:
    """Config sections a step may read: its stages' and their upstream stages', in config order."""
    used = {sec for s in closure(step_stages(step)) for sec in s.sections}
    return tuple(k for k in PipelineConfig.model_fields if k in used)


def step_config(step: str, config: dict[str, Any]) -> dict[str, Any]:
    """The part of a (JSON-dumped) pipeline config that ``step`` reads; nothing else reaches its task."""
    return {k: config[k] for k in step_sections(step) if k in config}


def key_material(step: str, config: dict[str, Any]) -> dict[str, Any]:
    """What identifies a step's computation besides its data inputs: versions and config sections of the
    step's stages and of all stages upstream of them."""
    return {"step": step,
            "versions": {k: v for s in closure(step_stages(step)) for k, v in s.versions().items()},
            "config": step_config(step, config)}


def manifest_versions() -> dict[str, str]:
    """``{package: version}`` of every stage (and perception backend), as recorded in a manifest."""
    return {k: v for s in all_stages().values() for k, v in s.versions().items()}


class ConfigView:
    """A ``PipelineConfig`` that lets a step read only the sections it declares (see module doc)."""

    def __init__(self, config: PipelineConfig, step: str) -> None:
        self._config, self._step, self._allowed = config, step, frozenset(step_sections(step))

    def __getattr__(self, name: str) -> Any:
        if name in PipelineConfig.model_fields and name not in self._allowed:
            raise ConfigError(f"step {self._step!r} reads config section {name!r}, which none of its stages "
                              f"{step_stages(self._step)} (or their upstream stages) declares: add it to the "
                              "stage's STAGE sections in its package __init__")
        return getattr(self._config, name)


def view(config: PipelineConfig | dict[str, Any], step: str) -> Any:
    """``config`` (a model, or a dumped dict of sections) seen by ``step``: a :class:`ConfigView`."""
    cfg = config if isinstance(config, PipelineConfig) else PipelineConfig().with_overrides(config)
    return ConfigView(cfg, step)
