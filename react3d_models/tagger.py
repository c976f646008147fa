"""Image tagger: CLIP zero-shot over a fixed indoor vocabulary, the documented RAM++ alternative.

RAM++ (the paper's tagger) has no installable package (only a GitHub repo with its own
dependencies), so tags come from CLIP through ``transformers``: per frame, the softmax over
"a photo of a <tag>." prompts; the top-k tags above a minimum probability are kept. The
vocabulary text embeddings are computed once per tagger.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch

from react3d_core.data.frames import Frame

from .host_sync import worker_stream
from .runtime import Loaded, preprocess, to_model


def select_tags(probs: np.ndarray, vocabulary: Sequence[str], top_k: int, min_prob: float) -> list[list[str]]:
    """Rows of (F,V) probabilities -> per frame the top_k tags with probability >= min_prob, best first."""
    order = np.argsort(-probs, axis=1, kind="stable")[:, :top_k]
    return [[vocabulary[j] for j in row if probs[i, j] >= min_prob] for i, row in enumerate(order)]


class ClipTagger:
    """Tagger protocol on CLIP image/text embeddings (batched images, text embedded once)."""

    def __init__(self, clip: Loaded, vocabulary: Sequence[str], top_k: int, min_prob: float, batch_size: int,
                 gpu_preprocess: bool = True) -> None:
        if not vocabulary:
            raise ValueError("the tag vocabulary is empty")
        self.clip, self.vocabulary, self.gpu_preprocess = clip, list(vocabulary), gpu_preprocess
        self.top_k, self.min_prob, self.batch_size = top_k, min_prob, batch_size
        self._text: torch.Tensor | None = None

    def _text_embeddings(self) -> torch.Tensor:
        if self._text is None:
            tok = self.clip.processor(text=[f"a photo of a {t}." for t in self.vocabulary], return_tensors="pt", padding=True)
            with torch.inference_mode():
                t = self.clip.model.get_text_features(input_ids=tok["input_ids"].to(self.clip.device),
                                                      attention_mask=tok["attention_mask"].to(self.clip.device))
            t = torch.nn.functional.normalize(getattr(t, "pooler_output", t).float(), dim=-1)
            if t.is_cuda:  # other threads read it from their own streams: complete before it is shared
                torch.cuda.current_stream(t.device).synchronize()
            self._text = t
        return self._text

    def probabilities(self, images: Sequence[np.ndarray]) -> np.ndarray:
        """(F,V) softmax over the vocabulary per image."""
        with worker_stream(self.clip.device):
            return self._probabilities(images)

    def _probabilities(self, images: Sequence[np.ndarray]) -> np.ndarray:
        text = self._text_embeddings()
        rows = []
        for s in range(0, len(images), self.batch_size):
            px = preprocess(self.clip.processor, self.clip.device, self.gpu_preprocess,
                            images=list(images[s : s + self.batch_size]))["pixel_values"]
            with torch.inference_mode():
                v = self.clip.model.get_image_features(**to_model({"pixel_values": px}, self.clip.device, self.clip.dtype))
                v = torch.nn.functional.normalize(getattr(v, "pooler_output", v).float(), dim=-1)
                scale = self.clip.model.logit_scale.exp().float()
                rows.append(torch.softmax(scale * v @ text.T, dim=-1).cpu().numpy())
        return np.concatenate(rows) if rows else np.zeros((0, len(self.vocabulary)))

    def tag(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[str]]:
        if len(frames) != len(images):
            raise ValueError(f"{len(frames)} frames but {len(images)} images")
        return select_tags(self.probabilities(images), self.vocabulary, self.top_k, self.min_prob)
