"""Randomly initialised checkpoints of the backend's models, saved with ``save_pretrained``.

Weights cannot be downloaded in tests or on closed benchmark machines, yet the loaders must be
exercised through the same ``from_pretrained`` path as real checkpoints. This module builds them from
configs: ``tiny`` (a few layers, 16-32 dims: CPU tests) or ``real`` (the released architectures:
Grounding DINO-T = Swin-T + BERT-base with 900 queries, SAM ViT-H or ViT-B, CLIP ViT-B/32), with
word-level tokenizers written here. Nothing is downloaded; the outputs are random.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import torch

Size = Literal["tiny", "real"]

# Word-level vocabulary for the BERT-style tokenizers of the detector and CLIP (ids < every vocab size).
WORDS = "[PAD] [UNK] [CLS] [SEP] [MASK] . a photo of cabinet door drawer oven wardrobe table chair floor".split()

SAM_VIT = {
    "vit_h": dict(hidden_size=1280, num_hidden_layers=32, num_attention_heads=16, global_attn_indexes=[7, 15, 23, 31]),
    "vit_b": dict(hidden_size=768, num_hidden_layers=12, num_attention_heads=12, global_attn_indexes=[2, 5, 8, 11]),
}


def word_tokenizer() -> Any:
    import transformers as tf

    return tf.BertTokenizer(vocab={w: i for i, w in enumerate(WORDS)})


def detector_config(size: Size) -> Any:
    """Grounding DINO: transformers' defaults are Grounding DINO-T; tiny has a 64 px Swin and 2 decoder
    layers (1 breaks weight tying)."""
    import transformers as tf

    if size == "real":
        return tf.GroundingDinoConfig()
    return tf.GroundingDinoConfig(
        backbone_config=tf.SwinConfig(image_size=64, patch_size=4, embed_dim=16, depths=[1, 1, 1, 1], num_heads=[1, 1, 1, 1],
                                      window_size=4, out_indices=[2, 3, 4]),
        text_config=tf.BertConfig(vocab_size=len(WORDS), hidden_size=32, num_hidden_layers=1, num_attention_heads=2,
                                  intermediate_size=32, max_position_embeddings=64),
        d_model=32, encoder_layers=1, decoder_layers=2, encoder_ffn_dim=32, decoder_ffn_dim=32, encoder_attention_heads=2,
        decoder_attention_heads=2, num_queries=20, num_feature_levels=4, encoder_n_points=2, decoder_n_points=2, max_text_len=32)


def sam_config(size: Size, variant: str = "vit_h") -> Any:
    """SAM at 1024 px (``variant`` vit_h or vit_b); tiny: 64 px input, 8 px patches, 16 channels."""
    import transformers as tf

    if size == "real":
        return tf.SamConfig(vision_config=SAM_VIT[variant])
    return tf.SamConfig(
        vision_config=dict(hidden_size=32, num_hidden_layers=1, num_attention_heads=2, image_size=64, patch_size=8,
                           output_channels=16, mlp_dim=32, global_attn_indexes=[0], window_size=4, num_pos_feats=8),
        prompt_encoder_config=dict(hidden_size=16, image_size=64, patch_size=8, mask_input_channels=4),
        mask_decoder_config=dict(hidden_size=16, num_hidden_layers=1, num_attention_heads=2, mlp_dim=32, iou_head_hidden_dim=16))


def clip_config(size: Size) -> Any:
    """CLIP ViT-B/32 (224 px) or a 32 px one-layer pair; both read the word-level vocabulary's ids."""
    import transformers as tf

    ids = dict(bos_token_id=2, eos_token_id=3, pad_token_id=0)
    if size == "real":
        return tf.CLIPConfig(text_config=dict(**ids), projection_dim=512)
    return tf.CLIPConfig(
        text_config=dict(vocab_size=len(WORDS), hidden_size=16, intermediate_size=32, num_hidden_layers=1, num_attention_heads=2,
                         max_position_embeddings=32, **ids),
        vision_config=dict(hidden_size=16, intermediate_size=32, num_hidden_layers=1, num_attention_heads=2, image_size=32, patch_size=8),
        projection_dim=16)


def _processors(size: Size) -> dict[str, Any]:
    import transformers as tf

    if size == "real":  # the released models' pre-processing (800/1333 px, 1024 px, 224 px)
        return {"detector": tf.GroundingDinoProcessor(image_processor=tf.GroundingDinoImageProcessor(), tokenizer=word_tokenizer()),
                "sam": tf.SamProcessor(image_processor=tf.SamImageProcessor()),
                "clip": tf.CLIPProcessor(image_processor=tf.CLIPImageProcessor(), tokenizer=word_tokenizer())}
    return {
        "detector": tf.GroundingDinoProcessor(image_processor=tf.GroundingDinoImageProcessor(size={"shortest_edge": 64, "longest_edge": 96}),
                                              tokenizer=word_tokenizer()),
        "sam": tf.SamProcessor(image_processor=tf.SamImageProcessor(size={"longest_edge": 64}, pad_size={"height": 64, "width": 64},
                                                                     mask_size={"longest_edge": 32})),
        "clip": tf.CLIPProcessor(image_processor=tf.CLIPImageProcessor(size={"shortest_edge": 32}, crop_size={"height": 32, "width": 32}),
                                 tokenizer=word_tokenizer()),
    }


def save_random_checkpoints(root: str | Path, size: Size = "tiny", sam_variant: str = "vit_h", seed: int = 0,
                            build_device: str | torch.device | None = None) -> dict[str, Path]:
    """Folders ``root/{gdino,sam,clip}`` loadable with ``from_pretrained``; returns {detector, sam, clip}.

    ``build_device``: where the random initialisation runs (a GPU initialises ViT-H in a second, the CPU
    in tens of seconds); the saved tensors are fp32 either way, like the released checkpoints."""
    import transformers as tf

    root = Path(root)
    torch.manual_seed(seed)
    procs = _processors(size)
    out: dict[str, Path] = {}
    for key, folder, cls, cfg in [("detector", "gdino", tf.GroundingDinoForObjectDetection, detector_config(size)),
                                  ("sam", "sam", tf.SamModel, sam_config(size, sam_variant)),
                                  ("clip", "clip", tf.CLIPModel, clip_config(size))]:
        path = root / folder
        path.mkdir(parents=True, exist_ok=True)
        with torch.device(build_device or "cpu"):
            model = cls(cfg)
        model.save_pretrained(path)
        del model
        procs[key].save_pretrained(path)
        out[key] = path
    return out
