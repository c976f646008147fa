"""Build the perception backend the config names: one entry point for every backend.

The weight-free backends live in the core. The ``models`` backend lives in its own package
(``react3d_models``: torch, transformers, weights) and is named here only by its module path, imported
when a config asks for it; the core's own import graph never contains it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from ..config import PerceptionConfig
from ..data.frames import SceneInput
from ..errors import ConfigError
from .interfaces import Perception

# backend name -> (module, builder taking the PerceptionConfig, what to install when the module is missing)
PLUGIN_BACKENDS: dict[str, tuple[str, str, str]] = {
    "models": ("react3d_models", "make_model_perception", "pip install -e '.[models]' (torch, transformers)"),
}


def make_perception(scene: SceneInput, config: PerceptionConfig) -> Perception:
    """``heuristic`` and ``oracle`` for this scene; ``models`` from ``perception.models`` (scene-independent:
    a worker can reuse it for every scene). Raises a one-line ConfigError when a backend cannot be built."""
    if config.backend == "heuristic":
        from .heuristic import make_heuristic

        return make_heuristic(scene, config)
    if config.backend == "oracle":
        if scene.gt_dir is None:
            raise ConfigError(f"the oracle backend needs ground truth, and scene {scene.scene_id} has none")
        from .oracle import make_oracle

        return make_oracle(scene, config)
    if config.backend in PLUGIN_BACKENDS:
        return plugin_builder(config.backend)(config)
    raise ConfigError(f"unknown perception backend {config.backend!r}")


def plugin_builder(backend: str) -> Callable[[PerceptionConfig], Perception]:
    """The builder of a backend that lives outside the core, imported now (its heavy imports with it)."""
    module, attr, install = PLUGIN_BACKENDS[backend]
    try:
        return getattr(importlib.import_module(module), attr)
    except ImportError as exc:
        why = next((ln.strip() for ln in str(exc).splitlines() if ln.strip()), type(exc).__name__)
        raise ConfigError(f"perception.backend={backend!r} needs the {module} package and its dependencies: {why}. "
                          f"Install them with {install}") from None
