"""Settings of the model backend that PerceptionConfig does not (yet) carry.

Read from ``config.models`` when the shared PerceptionConfig has such a nested sub-model, else the
defaults below; kept here so the model backend does not need edits to shared config files.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

# Objects a tagger should be able to name in indoor scans; openable ones and distractors (the tag
# filter must have something to reject). Used by the CLIP zero-shot tagger (RAM++ alternative).
DEFAULT_VOCABULARY: tuple[str, ...] = (
    "cabinet", "kitchen cabinet", "wardrobe", "closet", "dresser", "drawer", "chest of drawers",
    "nightstand", "cupboard", "refrigerator", "oven", "microwave", "dishwasher", "washing machine",
    "door", "sliding door", "shelf", "bookshelf", "sink", "countertop", "table", "chair", "sofa",
    "bed", "lamp", "window", "curtain", "television", "plant", "box", "floor", "wall", "ceiling",
)


class ModelOptions(BaseModel):
    """Knobs of the foundation-model adapters (defaults follow the paper where it says anything)."""

    model_config = ConfigDict(extra="forbid")

    dtype: str = Field("auto", description="'auto' (bf16 on GPUs that have it, else fp16; fp32 on CPU), 'fp32', 'fp16', 'bf16'.")
    clip_model: str = Field("openai/clip-vit-base-patch32", description="CLIP for the zero-shot tagger (RAM++ alternative).")
    tag_vocabulary: tuple[str, ...] = Field(DEFAULT_VOCABULARY, description="Tags the CLIP tagger chooses from.")
    tag_top_k: int = Field(8, ge=1, description="At most this many tags per frame.")
    tag_min_prob: float = Field(0.03, ge=0, le=1, description="Softmax probability (over the vocabulary) a tag needs.")
    llm_timeout_s: float = Field(60.0, gt=0, description="Per-request timeout of the chat endpoint.")
    llm_retries: int = Field(3, ge=0, description="Retries after a failed/malformed chat reply.")
    llm_backoff_s: float = Field(1.0, ge=0, description="First retry delay; doubles each retry.")
    llm_max_new_tokens: int = Field(256, ge=8, description="Reply length of the local tag-filter LM.")
    max_detections: int = Field(100, ge=1, description="At most this many boxes per frame after NMS (each costs a full-size mask).")
    gpu_preprocess: bool = Field(True, description="Resize/normalise frames on the GPU when the processors have a torch backend.")
    articulation_timeout_s: float = Field(300.0, gt=0, description="Timeout of one OPDMulti request/command.")
    articulation_min_score: float = Field(0.5, ge=0, le=1, description="OPDMulti predictions below this score are dropped.")


def model_options(config: Any) -> ModelOptions:
    """The ModelOptions of a PerceptionConfig (its ``models`` field if it has one)."""
    raw = getattr(config, "models", None)
    if raw is None:
        return ModelOptions()
    if isinstance(raw, ModelOptions):
        return raw
    data = raw.model_dump() if hasattr(raw, "model_dump") else dict(raw)
    return ModelOptions.model_validate({k: v for k, v in data.items() if k in ModelOptions.model_fields})
