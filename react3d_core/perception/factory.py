"""Choose the weight-free perception backend named in the config (models live in tasks/models)."""

from __future__ import annotations

from ..config import PerceptionConfig
from ..data.frames import SceneInput
from ..errors import ConfigError
from .interfaces import Perception


def make_perception(scene: SceneInput, config: PerceptionConfig) -> Perception:
    """``heuristic`` or ``oracle``; ``models`` needs weights and is built by ``tasks.models``."""
    if config.backend == "heuristic":
        from .heuristic import make_heuristic

        return make_heuristic(scene, config)
    if config.backend == "oracle":
        if scene.gt_dir is None:
            raise ConfigError(f"the oracle backend needs ground truth, and scene {scene.scene_id} has none")
        from .oracle import make_oracle

        return make_oracle(scene, config)
    raise ConfigError(
        f"backend {config.backend!r} loads model weights: build it with tasks.models.make_model_perception"
    )
