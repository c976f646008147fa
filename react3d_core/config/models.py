"""The ``perception.models`` section: every setting of the foundation-model backend (``react3d_models``).

Pure pydantic, like every config module: the section can be read, validated and recorded on a machine
without torch; only ``react3d_models`` reads it to load and call the models.
"""

from __future__ import annotations

import re
from typing import Literal
from urllib.parse import parse_qsl, urlsplit

from pydantic import Field, ValidationInfo, field_validator

from ..errors import ConfigError
from ._base import StageConfig

# Objects a tagger should be able to name in indoor scans; openable ones and distractors (the tag
# filter must have something to reject). Used by the CLIP zero-shot tagger (RAM++ alternative).
DEFAULT_VOCABULARY: tuple[str, ...] = (
    "cabinet", "kitchen cabinet", "wardrobe", "closet", "dresser", "drawer", "chest of drawers",
    "nightstand", "cupboard", "refrigerator", "oven", "microwave", "dishwasher", "washing machine",
    "door", "sliding door", "shelf", "bookshelf", "sink", "countertop", "table", "chair", "sofa",
    "bed", "lamp", "window", "curtain", "television", "plant", "box", "floor", "wall", "ceiling",
)


class ModelsConfig(StageConfig):
    """The foundation-model backend (``perception.backend = "models"``): which weights, where they run, and
    how each model is called. Defaults follow the paper where it says anything."""

    # where and how the models run
    device: str = Field("auto", pattern=r"^(auto|cpu|cuda(:[0-9]+)?)$",
                        description="'auto' (the first CUDA GPU, else the CPU), 'cpu', 'cuda' or 'cuda:N'.")
    dtype: Literal["auto", "fp32", "fp16", "bf16"] = Field(
        "auto", description="Weights and activations: 'auto' is bf16 on GPUs that have it, else fp16, and fp32 on the CPU.")
    batch_size: int = Field(8, ge=1, description="Frames per model forward (detector, SAM encoder, CLIP) and per OPDMulti "
                                                 "request; perception.batch_size frames reach the backend per call.")
    gpu_preprocess: bool = Field(True, description="Resize/normalise frames on the GPU when the processors have a torch backend.")
    # text-prompted segmentation: Grounding DINO boxes, SAM masks
    detector_model: str = Field("IDEA-Research/grounding-dino-tiny", description="Open-vocabulary detector, Grounding DINO (hub id or local folder).")
    box_threshold: float = Field(0.3, ge=0, le=1, description="Grounding DINO box threshold (paper: 0.3).")
    text_threshold: float = Field(0.25, ge=0, le=1, description="Grounding DINO text threshold (paper: 0.25).")
    nms_iou: float = Field(0.8, ge=0, le=1, description="Boxes overlapping a better one by more than this IoU are dropped (Grounded-SAM demo: 0.8).")
    max_detections: int = Field(100, ge=1, description="At most this many boxes per frame after NMS (each costs a full-size mask).")
    sam_model: str = Field("facebook/sam-vit-huge", description="SAM or SAM 2, for box and point prompts (hub id or local folder).")
    # tags
    tagger_model: str = Field("xinyu1205/recognize-anything-plus-model",
                              description="Image tagger: a CLIP id/folder, or the paper's RAM++ id, which selects the CLIP tagger clip_model.")
    clip_model: str = Field("openai/clip-vit-base-patch32", description="CLIP for the zero-shot tagger that stands in for RAM++ (not installable).")
    tag_vocabulary: tuple[str, ...] = Field(DEFAULT_VOCABULARY, min_length=1, description="Tags the CLIP tagger chooses from.")
    tag_top_k: int = Field(8, ge=1, description="At most this many tags per frame.")
    tag_min_prob: float = Field(0.03, ge=0, le=1, description="Softmax probability (over the vocabulary) a tag needs.")
    # openable-tag filter
    tag_filter_endpoint: str | None = Field(None, description="OpenAI-compatible chat endpoint for the openable-tag filter "
                                                              "(null: the local language model tag_filter_model).")
    tag_filter_model: str = Field("llava-hf/llava-1.5-7b-hf", description="Tag-filter language model (the endpoint's model name, or a local hub id/folder).")
    llm_timeout_s: float = Field(60.0, gt=0, description="Per-request timeout of the chat endpoint.")
    llm_retries: int = Field(3, ge=0, description="Retries after a failed/malformed chat reply.")
    llm_backoff_s: float = Field(1.0, ge=0, description="First retry delay of the chat endpoint; doubles each retry.")
    llm_endpoint_max_tokens: int = Field(512, ge=8, description="Reply length (max_tokens) asked of the chat endpoint.")
    llm_max_new_tokens: int = Field(256, ge=8, description="Reply length of the local tag-filter language model.")
    # articulation predictor
    articulation_endpoint: str | None = Field(None, description="OPDMulti HTTP endpoint or command (JSON contract; null: no per-view predictions).")
    articulation_timeout_s: float = Field(300.0, gt=0, description="Timeout of one OPDMulti request/command.")
    articulation_retries: int = Field(2, ge=0, description="Retries of a failed OPDMulti request (transport errors, HTTP 5xx/429).")
    articulation_backoff_s: float = Field(1.0, ge=0, description="First retry delay of OPDMulti; doubles each retry.")
    articulation_min_score: float = Field(0.5, ge=0, le=1, description="OPDMulti predictions below this score are dropped.")

    @field_validator("tag_vocabulary")
    @classmethod
    def _distinct_tags(cls, value: tuple[str, ...]) -> tuple[str, ...]:
        """A blank or repeated tag would split the softmax between identical prompts."""
        blank = [i for i, t in enumerate(value) if not t.strip()]
        if blank:
            raise ValueError(f"tag {blank[0]} is blank")
        seen: set[str] = set()
        for t in value:
            if t.strip().lower() in seen:
                raise ValueError(f"tag {t!r} is listed twice")
            seen.add(t.strip().lower())
        return value

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
                raise ConfigError(f"perception.models.{field} carries a credential ({where}); it would be stored in "
                                  "scene.json and Prefect's run parameters. Remove it and set the key in the environment "
                                  "(REACT3D_LLM_API_KEY, REACT3D_OPDMULTI_API_KEY; docs/reliability.md) "
                                  "or in a Prefect Secret block")
        return value


# Settings of the model backend that used to sit directly in the perception section.
MOVED_TO_MODELS: tuple[str, ...] = ("device", "detector_model", "sam_model", "tagger_model", "tag_filter_endpoint",
                                    "tag_filter_model", "articulation_endpoint", "box_threshold", "text_threshold")


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
