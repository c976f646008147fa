"""Foundation-model perception backend (the only code that loads weights or touches a GPU).

``make_model_perception(config)`` builds the five calls of the paper from PerceptionConfig:
Grounding DINO + SAM (text prompts), SAM (point prompts), a CLIP zero-shot tagger (RAM++ alternative),
an openable-tag filter (OpenAI-compatible endpoint or local LM) and OPDMulti over a JSON contract.
Each model is loaded once per worker process (runtime.load_cached); nothing is downloaded at import.
"""

from __future__ import annotations

import logging

from react3d_core.config import PerceptionConfig
from react3d_core.perception.interfaces import ArticulationPredictor, Perception

from .grounded_sam import GroundedSamSegmenter, SamPointSegmenter
from .loaders import load_causal_lm, load_clip, load_detector, load_sam
from .opdmulti import NoArticulationPredictor, OPDMultiClient
from .options import ModelOptions, model_options
from .runtime import ModelNeed, ModelUnavailableError, api_key, check_models_available, load_cached, resolve_device, resolve_dtype
from .tag_filter import CachedTagFilter, chat_asker, local_lm_asker
from .tagger import ClipTagger
from .version import STAGE_VERSION

log = logging.getLogger(__name__)

__all__ = ["STAGE_VERSION", "make_model_perception", "ModelOptions", "ModelUnavailableError"]


def _tagger_id(config: PerceptionConfig, opts: ModelOptions) -> str:
    """RAM++ has no installable package: a RAM++ id means 'use the CLIP alternative'."""
    tid = config.tagger_model
    if "recognize-anything" in tid.lower() or tid.lower().rsplit("/", 1)[-1].startswith("ram"):
        log.info("tagger %s (RAM++) is not installable; using CLIP zero-shot tagger %s", tid, opts.clip_model)
        return opts.clip_model
    return tid


def make_model_perception(config: PerceptionConfig) -> Perception:
    """The ``models`` backend; raises ModelUnavailableError (one line) when a model's weights are missing."""
    opts = model_options(config)
    device = resolve_device(config.device)
    dtype = resolve_dtype(opts.dtype, device)
    needs = [ModelNeed("Grounding DINO", config.detector_model, "detector_model"),
             ModelNeed("SAM", config.sam_model, "sam_model"),
             ModelNeed("CLIP tagger", _tagger_id(config, opts), "tagger_model")]
    if not config.tag_filter_endpoint:
        needs.append(ModelNeed("tag-filter language model", config.tag_filter_model, "tag_filter_model"))
    check_models_available(needs)  # offline first: seconds, not minutes of hub retries
    det = load_cached("detector", config.detector_model, device, dtype, load_detector, "Grounding DINO", "detector_model")
    sam = load_cached("sam", config.sam_model, device, dtype, load_sam, "SAM", "sam_model")
    clip = load_cached("clip", _tagger_id(config, opts), device, dtype, load_clip, "CLIP tagger", "tagger_model")
    if config.tag_filter_endpoint:
        ask = chat_asker(config.tag_filter_endpoint, config.tag_filter_model, opts.llm_timeout_s, opts.llm_retries,
                         opts.llm_backoff_s, api_key=api_key(("REACT3D_LLM_API_KEY", "OPENAI_API_KEY"), "REACT3D_LLM_API_KEY_BLOCK"))
        retries = opts.llm_retries
    else:
        lm = load_cached("lm", config.tag_filter_model, device, dtype, load_causal_lm, "tag-filter language model", "tag_filter_model")
        ask = local_lm_asker(lm, opts.llm_max_new_tokens)
        retries = 0  # greedy decoding: asking again gives the same reply
    articulation: ArticulationPredictor
    if config.articulation_endpoint:
        articulation = OPDMultiClient(config.articulation_endpoint, opts.articulation_timeout_s, opts.articulation_min_score,
                                      batch_size=config.batch_size,
                                      api_key=api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK"))
    else:
        articulation = NoArticulationPredictor()
    return Perception(
        name="models",
        tagger=ClipTagger(clip, opts.tag_vocabulary, opts.tag_top_k, opts.tag_min_prob, config.batch_size, opts.gpu_preprocess),
        tag_filter=CachedTagFilter(ask, config.always_keep_tags, retries, opts.llm_backoff_s),
        segmenter=GroundedSamSegmenter(det, sam, config.box_threshold, config.text_threshold, config.batch_size,
                                        max_detections=opts.max_detections, gpu_preprocess=opts.gpu_preprocess),
        point_segmenter=SamPointSegmenter(sam),
        articulation=articulation,
        version=STAGE_VERSION,
    )
