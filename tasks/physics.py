"""The physics check as a cached Prefect task: keyed by the export's content (its store folder's hash),
the physics config and the stage versions, so a re-convert of an unchanged export reuses the result."""

from __future__ import annotations

from typing import Any

from prefect import task

from react3d_core.config import PhysicsConfig
from react3d_core.pipeline import check_physics as check_step
from react3d_core.pipeline import step_config

from .keys import content_key
from .store import resolve


def check_body(exported: dict[str, Any], config: dict[str, Any]) -> dict[str, Any]:
    """The check of the exported store folder (read only); the full result as a JSON dict."""
    return check_step(resolve(exported["path"]).parent, PhysicsConfig.model_validate(config.get("physics", {})))


@task(name="physics-check", cache_key_fn=content_key("physics"), result_serializer="json", cache_result_in_memory=False)
def check_physics(exported: dict[str, Any], config: dict[str, Any]) -> dict[str, Any]:
    """Drive every joint in the configured simulators and probe cavities and fronts (docs/physics.md)."""
    return check_body(exported, step_config("physics", config))
