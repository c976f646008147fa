"""Perception backends and their thresholds (tags, 2D masks, point prompts, articulation predictor)."""

import re
from typing import Literal
from urllib.parse import parse_qsl, urlsplit

from pydantic import Field, ValidationInfo, field_validator

from ..errors import ConfigError
from ._base import StageConfig
from .heuristic import HeuristicConfig


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
    box_threshold: float = Field(0.3, ge=0, le=1, description="Grounding DINO box threshold (paper: 0.3).")
    text_threshold: float = Field(0.25, ge=0, le=1, description="Grounding DINO text threshold (paper: 0.25).")
    always_keep_tags: tuple[str, ...] = Field(("door",), description="Tags kept whatever the tag filter says.")
    prompt_suffix: str = Field(" door", description="Phrase for openable tags, e.g. 'cabinet' -> 'cabinet door'.")
    hole_close_px: int = Field(30, ge=0, description="Closing kernel (px at 960x720) that fills missed handles in masks.")
    detector_model: str = Field("IDEA-Research/grounding-dino-tiny", description="Open-vocabulary detector (hub id or local path).")
    sam_model: str = Field("facebook/sam-vit-huge", description="SAM (hub id or local path).")
    tagger_model: str = Field("xinyu1205/recognize-anything-plus-model", description="Image tagger (RAM++ or alternative).")
    tag_filter_endpoint: str | None = Field(None, description="OpenAI-compatible chat endpoint for the openable-tag filter.")
    tag_filter_model: str = Field("llava-hf/llava-1.5-7b-hf", description="Tag-filter language model (endpoint model name or local id).")
    articulation_endpoint: str | None = Field(None, description="OPDMulti HTTP endpoint or command (JSON contract).")
    batch_size: int = Field(8, ge=1, description="Frames per model call on GPU.")
    device: str = Field("auto", description="'auto', 'cpu', 'cuda', 'cuda:N'.")
    oracle: OracleNoiseConfig = Field(default_factory=OracleNoiseConfig, description="Oracle backend: how imperfect its ground truth is made.")
    heuristic: HeuristicConfig = Field(default_factory=HeuristicConfig, description="Heuristic backend: facets, front rules, image path, sliding doors.")

    @field_validator("tag_filter_endpoint", "articulation_endpoint")
    @classmethod
    def _no_credentials(cls, value: str | None, info: ValidationInfo) -> str | None:
        """Endpoints are recorded in scene.json and in Prefect's flow-run parameters, so they must not carry a
        secret: keys come from the environment (REACT3D_LLM_API_KEY / OPENAI_API_KEY,
        REACT3D_OPDMULTI_API_KEY) or a Prefect Secret block, never from the config."""
        if value:
            where = endpoint_credential(value)
            if where:
                field = info.field_name
                # ConfigError, not ValueError: pydantic would wrap a ValueError and echo the input (the key)
                raise ConfigError(f"perception.{field} carries a credential ({where}); it would be stored in scene.json "
                                 "and Prefect's run parameters. Remove it and set the key in the environment "
                                 "(REACT3D_LLM_API_KEY, REACT3D_OPDMULTI_API_KEY; docs/reliability.md) "
                                 "or in a Prefect Secret block")
        return value


_URL = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*://[^\s'\"]+")
_SECRET_NAME = re.compile(r"^(.*[-_])?(api[-_]?key|key|token|access[-_]?token|secret|password|passwd|pwd|auth|"
                          r"authorization|signature|sig|credentials?)$", re.IGNORECASE)
_SECRET_FLAG = re.compile(r"(?:^|\s)--?(api[-_]?key|token|access[-_]?token|secret|password|auth)(?:[=\s]|$)", re.IGNORECASE)


def endpoint_credential(value: str) -> str | None:
    """Where ``value`` (a URL, or a command that may contain URLs) carries a credential, else None:
    user info in a URL, a query parameter named like a key/token, or a ``--api-key``-style flag."""
    for url in _URL.findall(value):
        parts = urlsplit(url)
        if "@" in parts.netloc:
            return "user name/password in the URL"
        for name, _ in parse_qsl(parts.query, keep_blank_values=True):
            if _SECRET_NAME.match(name):
                return f"query parameter {name!r}"
    m = _SECRET_FLAG.search(value)
    return f"command-line flag {m.group(0).strip().split('=')[0]!r}" if m else None

