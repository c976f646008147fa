"""``make_model_perception``: the five calls of the paper built from the ``perception.models`` section.

Each model is loaded once per worker process (runtime.load_cached); nothing is downloaded at import.
"""

from __future__ import annotations

import logging

from react3d_core.config import ModelsConfig, PerceptionConfig
from react3d_core.perception.interfaces import ArticulationPredictor, Perception

from .grounded_sam import GroundedSamSegmenter, SamPointSegmenter
from .loaders import load_causal_lm, load_clip, load_detector, load_sam
from .opdmulti import NoArticulationPredictor, OPDMultiClient
from .runtime import ModelNeed, api_key, check_models_available, load_cached, resolve_device, resolve_dtype
from .tag_filter import CachedTagFilter, chat_asker, local_lm_asker
from .tagger import ClipTagger
from .version import STAGE_VERSION

log = logging.getLogger(__name__)


def tagger_id(m: ModelsConfig) -> str:
    """RAM++ has no installable package: a RAM++ id means 'use the CLIP alternative' (``clip_model``)."""
    tid = m.tagger_model
    if "recognize-anything" in tid.lower() or tid.lower().rsplit("/", 1)[-1].startswith("ram"):
        log.info("tagger %s (RAM++) is not installable; using CLIP zero-shot tagger %s", tid, m.clip_model)
        return m.clip_model
    return tid


def make_model_perception(config: PerceptionConfig) -> Perception:
    """The ``models`` backend; raises ModelUnavailableError (one line) when a model's weights are missing."""
    m = config.models
    device = resolve_device(m.device)
    dtype = resolve_dtype(m.dtype, device)
    tagger = tagger_id(m)
    tagger_field = "tagger_model" if tagger == m.tagger_model else "clip_model"  # the field a fix would change
    needs = [ModelNeed("Grounding DINO", m.detector_model, "detector_model"),
             ModelNeed("SAM", m.sam_model, "sam_model"),
             ModelNeed("CLIP tagger", tagger, tagger_field)]
    if not m.tag_filter_endpoint:
        needs.append(ModelNeed("tag-filter language model", m.tag_filter_model, "tag_filter_model"))
    check_models_available(needs)  # offline first: seconds, not minutes of hub retries
    det = load_cached("detector", m.detector_model, device, dtype, load_detector, "Grounding DINO", "detector_model")
    sam = load_cached("sam", m.sam_model, device, dtype, load_sam, "SAM", "sam_model")
    clip = load_cached("clip", tagger, device, dtype, load_clip, "CLIP tagger", tagger_field)
    if m.tag_filter_endpoint:
        ask = chat_asker(m.tag_filter_endpoint, m.tag_filter_model, m.llm_timeout_s, m.llm_retries, m.llm_backoff_s,
                         api_key=api_key(("REACT3D_LLM_API_KEY", "OPENAI_API_KEY"), "REACT3D_LLM_API_KEY_BLOCK"),
                         max_tokens=m.llm_endpoint_max_tokens)
        retries = m.llm_retries
    else:
        lm = load_cached("lm", m.tag_filter_model, device, dtype, load_causal_lm, "tag-filter language model", "tag_filter_model")
        ask = local_lm_asker(lm, m.llm_max_new_tokens)
        retries = 0  # greedy decoding: asking again gives the same reply
    articulation: ArticulationPredictor
    if m.articulation_endpoint:
        articulation = OPDMultiClient(m.articulation_endpoint, m.articulation_timeout_s, m.articulation_min_score,
                                      retries=m.articulation_retries, backoff_s=m.articulation_backoff_s,
                                      batch_size=m.batch_size,
                                      api_key=api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK"))
    else:
        articulation = NoArticulationPredictor()
    return Perception(
        name="models",
        tagger=ClipTagger(clip, m.tag_vocabulary, m.tag_top_k, m.tag_min_prob, m.batch_size, m.gpu_preprocess),
        tag_filter=CachedTagFilter(ask, config.always_keep_tags, retries, m.llm_backoff_s),
        segmenter=GroundedSamSegmenter(det, sam, m.box_threshold, m.text_threshold, m.batch_size, nms_iou=m.nms_iou,
                                        max_detections=m.max_detections, gpu_preprocess=m.gpu_preprocess),
        point_segmenter=SamPointSegmenter(sam),
        articulation=articulation,
        version=STAGE_VERSION,
    )
