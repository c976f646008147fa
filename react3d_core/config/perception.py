"""Perception backends and their thresholds (tags, 2D masks, point prompts, articulation predictor)."""

from typing import Any, Literal

from pydantic import Field, model_validator

from ..errors import ConfigError
from ._base import StageConfig
from .heuristic import HeuristicConfig
from .models import MOVED_TO_MODELS, ModelsConfig


class OracleNoiseConfig(StageConfig):
    """Realism of the oracle backend (ground-truth masks/articulations made imperfect on purpose)."""

    boundary_px: int = Field(2, description="Erode (<0) or dilate (>0) GT masks by this many pixels at 960 px width.")
    handle_holes: bool = Field(False, description="Remove handle pixels from part masks (like Grounded-SAM missing handles).")
    drop_rate: float = Field(0.1, ge=0, le=1, description="Probability that a visible part is not detected in a frame.")
    merge_rate: float = Field(0.0, ge=0, le=1, description="Probability that two adjacent parts come out as one mask.")
    whole_object_rate: float = Field(0.0, ge=0, le=1, description="Probability that a mask covers the whole object (part + frame).")
    false_positive_rate: float = Field(0.0, ge=0, description="Expected false-positive masks per frame.")
    min_visible_px: int = Field(100, ge=0, description="Parts with fewer visible pixels in a frame are not reported.")
    axis_noise_deg: float = Field(7.0, ge=0, description="Std-dev-like angular noise on initial axes (OPDMulti-like: ~7 deg).")
    origin_noise_m: float = Field(0.2, ge=0, description="Positional noise on initial origins (OPDMulti-like: ~0.2 m).")
    type_flip_rate: float = Field(0.0, ge=0, le=1, description="Probability that the initial joint type is wrong.")
    seed: int = Field(0, description="Seed of the oracle's noise.")




class PerceptionConfig(StageConfig):
    """Which backend runs each model call, and the paper's thresholds."""

    backend: Literal["heuristic", "oracle", "models"] = Field(
        "heuristic", description="heuristic: weight-free RGB-D; oracle: ground truth (+noise); models: foundation models."
    )
    always_keep_tags: tuple[str, ...] = Field(("door",), description="Tags kept whatever the tag filter says.")
    prompt_suffix: str = Field(" door", description="Phrase for openable tags, e.g. 'cabinet' -> 'cabinet door'.")
    hole_close_px: int = Field(30, ge=0, description="Closing kernel (px at 960x720) that fills missed handles in masks.")
    batch_size: int = Field(8, ge=1, description="Frames per perception call (one Prefect task), whatever the backend.")
    oracle: OracleNoiseConfig = Field(default_factory=OracleNoiseConfig, description="Oracle backend: how imperfect its ground truth is made.")
    heuristic: HeuristicConfig = Field(default_factory=HeuristicConfig, description="Heuristic backend: facets, front rules, image path, sliding doors.")
    models: ModelsConfig = Field(default_factory=ModelsConfig, description="Models backend: weights, device, dtype, thresholds, endpoints.")

    @model_validator(mode="before")
    @classmethod
    def _moved_keys(cls, data: Any) -> Any:
        """The model backend's settings moved into ``perception.models``: say where, instead of 'extra inputs
        are not permitted' (the value is not echoed: an endpoint may carry a key)."""
        if isinstance(data, dict):
            moved = [k for k in MOVED_TO_MODELS if k in data]
            if moved:
                raise ConfigError("; ".join(f"perception.{k} is now perception.models.{k}" for k in moved)
                                  + " (the models backend's settings are one section: docs/perception_models.md)")
        return data
