"""Foundation-model perception backend: the only code in REACT3D that loads weights or touches a GPU.

``make_model_perception(config)`` builds the five calls of the paper from ``perception.models``
(:class:`react3d_core.config.ModelsConfig`): Grounding DINO + SAM (text prompts), SAM (point prompts), a
CLIP zero-shot tagger (RAM++ alternative), an openable-tag filter (OpenAI-compatible endpoint or local LM)
and OPDMulti over a JSON contract. The perception factory of the core builds it on demand
(``react3d_core.perception.make_perception`` with ``backend="models"``).

Depends on ``react3d_core``, torch and transformers, never on ``tasks`` or ``flows``. Importing this
package (or ``react3d_models.version``) loads neither torch nor transformers: the backend module is
imported when one of its names is first used, so cache keys can name the version on any machine.
"""

from __future__ import annotations

from typing import Any

from .version import STAGE_VERSION

__all__ = ["STAGE_VERSION", "ModelUnavailableError", "make_model_perception"]

_LAZY = {"make_model_perception": "backend", "ModelUnavailableError": "runtime"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
