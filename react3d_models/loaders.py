"""``from_pretrained`` loaders for each model kind (hub id or local folder), used through the cache."""

from __future__ import annotations

from typing import Any

import torch

from .host_sync import cache_sam_relative_positions, skip_shape_checks
from .runtime import Loaded, hub_kwargs, pretrained


def load_detector(model_id: str, device: torch.device, dtype: torch.dtype) -> Loaded:
    """Grounding DINO (GroundingDinoForObjectDetection + its processor); on a GPU without its input checks
    that wait for the device (host_sync.skip_shape_checks)."""
    from transformers import AutoProcessor, GroundingDinoForObjectDetection

    if device.type == "cuda":
        skip_shape_checks()
    proc = AutoProcessor.from_pretrained(model_id, **hub_kwargs(model_id))
    return Loaded(pretrained(GroundingDinoForObjectDetection, model_id, device, dtype), proc, device, dtype)


def load_sam(model_id: str, device: torch.device, dtype: torch.dtype) -> Loaded:
    """SAM or SAM 2, chosen by the checkpoint's model_type; SAM's relative-position tables computed once per layer."""
    from transformers import AutoConfig

    model_type = AutoConfig.from_pretrained(model_id, **hub_kwargs(model_id)).model_type
    if model_type.startswith("sam2"):
        from transformers import Sam2Model as Model, Sam2Processor as Proc
    else:
        from transformers import SamModel as Model, SamProcessor as Proc
    model = pretrained(Model, model_id, device, dtype)
    if not model_type.startswith("sam2"):
        cache_sam_relative_positions(model)
    return Loaded(model, Proc.from_pretrained(model_id, **hub_kwargs(model_id)), device, dtype)


def load_clip(model_id: str, device: torch.device, dtype: torch.dtype) -> Loaded:
    """CLIP (image + text towers) for the zero-shot tagger."""
    from transformers import CLIPModel, CLIPProcessor

    return Loaded(pretrained(CLIPModel, model_id, device, dtype), CLIPProcessor.from_pretrained(model_id, **hub_kwargs(model_id)), device, dtype)


def load_causal_lm(model_id: str, device: torch.device, dtype: torch.dtype) -> Loaded:
    """A text-generation model for the tag filter: a causal LM, or a vision-language model (LLaVA) used text-only."""
    from transformers import AutoConfig, AutoModelForCausalLM, AutoTokenizer

    cfg = AutoConfig.from_pretrained(model_id, **hub_kwargs(model_id))
    model: Any
    if type(cfg) in AutoModelForCausalLM._model_mapping:
        model, proc = pretrained(AutoModelForCausalLM, model_id, device, dtype), AutoTokenizer.from_pretrained(model_id, **hub_kwargs(model_id))
    else:
        from transformers import AutoModelForImageTextToText, AutoProcessor

        model, proc = pretrained(AutoModelForImageTextToText, model_id, device, dtype), AutoProcessor.from_pretrained(model_id, **hub_kwargs(model_id))
    return Loaded(model, proc, device, dtype)
