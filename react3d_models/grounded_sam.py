"""Grounded-SAM through ``transformers``: Grounding DINO boxes for text phrases, SAM masks for the boxes.

Batched: one detector forward and one SAM image-encoder forward per batch of frames (the expensive
parts); the SAM mask decoder then runs per frame with all of that frame's boxes at once. Masks come
back at each frame's RGB resolution (hole filling is the fusion stage's job). SAM 2 checkpoints
(``facebook/sam2*``) are supported through Sam2Model/Sam2Processor, run per frame (simplified path).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from react3d_core.data.frames import Frame
from react3d_core.data.masks import Mask2D

from .host_sync import masks_to_host, worker_stream
from .runtime import Loaded, preprocess, to_model


def detector_prompt(phrases: Sequence[str]) -> str:
    """Grounding DINO's text format: lower-case phrases, each ended by ' .' (as in its model card)."""
    return " ".join(p.strip().lower().rstrip(".") + "." for p in phrases if p.strip())


_SPECIAL = {"[cls]", "[sep]", "[pad]", "[unk]", "[mask]", "<s>", "</s>", "<pad>", "<unk>"}


def phrase_groups(phrases: Sequence[str], tokenizer: Any, max_tokens: int) -> list[list[str]]:
    """Split phrases into prompts that fit Grounding DINO's text length (256 tokens for the released
    models); longer prompts would be truncated and their last phrases never detected."""
    groups: list[list[str]] = [[]]
    for p in phrases:
        trial = groups[-1] + [p]
        if groups[-1] and len(tokenizer(detector_prompt(trial))["input_ids"]) > max_tokens:
            groups.append([p])
        else:
            groups[-1] = trial
    return [g for g in groups if g]


def match_phrase(label: str, phrases: Sequence[str]) -> str:
    """Map a decoded Grounding DINO label (sub-phrase tokens) to the prompt phrase sharing most words,
    ties going to the phrase with fewest words the label lacks ('door' -> 'door', not 'cabinet door')."""
    words = set(label.lower().replace(".", " ").split()) - _SPECIAL
    best, best_key = " ".join(w for w in label.lower().split() if w not in _SPECIAL) or "openable", (0, 0)
    for p in phrases:
        pw = set(p.lower().split())
        key = (len(words & pw), -len(pw - words))
        if key[0] > 0 and key > best_key:
            best, best_key = p, key
    return best


def is_sam2(loaded: Loaded) -> bool:
    return type(loaded.model).__name__.startswith("Sam2")


@dataclass
class Detection:
    """Boxes (N,4 x0y0x1y1 px of the original image), scores (N,), labels (N phrases)."""

    boxes: np.ndarray
    scores: np.ndarray
    labels: list[str]


def top_queries(logits: torch.Tensor, boxes: torch.Tensor, keep: int) -> tuple[torch.Tensor, torch.Tensor]:
    """The ``keep`` queries of each image with the highest token score, in score order ((B,Q,T), (B,Q,4) ->
    (B,keep,T), (B,keep,4)). Post-processing decodes a text label per box above the threshold in Python:
    on a 1920x1440 frame that was 150 ms of Grounding DINO's 177 ms when many of its 900 queries passed."""
    if keep <= 0 or logits.shape[1] <= keep:
        return logits, boxes
    idx = logits.sigmoid().amax(-1).topk(keep, dim=1).indices
    return (torch.gather(logits, 1, idx[..., None].expand(-1, -1, logits.shape[-1])),
            torch.gather(boxes, 1, idx[..., None].expand(-1, -1, boxes.shape[-1])))


def detect(det: Loaded, images: Sequence[np.ndarray], phrases: Sequence[str],
           box_threshold: float, text_threshold: float, on_device: bool = True, keep_queries: int = 0) -> list[Detection]:
    """One batched Grounding DINO forward; boxes mapped back to each image's own pixel size. ``on_device``:
    resize and normalise on the GPU when the processor can (see runtime.preprocess); ``keep_queries`` > 0:
    only that many best queries per image are post-processed."""
    prompt = detector_prompt(phrases)
    inputs = preprocess(det.processor, det.device, on_device, images=list(images), text=[prompt] * len(images), padding=True)
    inputs = to_model(inputs, det.device, det.dtype)
    with torch.inference_mode():
        out = det.model(**inputs)
    logits, boxes = top_queries(out.logits.float(), out.pred_boxes.float(), keep_queries)
    # post-processing on the host: on GPU tensors it read every token id of every box back one by one
    # (13 000 waits for 32 frames on an H100); one copy of the kept queries instead
    out.logits, out.pred_boxes = logits.cpu(), boxes.cpu()
    return detections_from_outputs(det.processor, out, inputs["input_ids"].cpu(), [im.shape[:2] for im in images],
                                   phrases, box_threshold, text_threshold)


def detections_from_outputs(processor: Any, out: Any, input_ids: torch.Tensor, sizes: Sequence[tuple[int, int]],
                            phrases: Sequence[str], box_threshold: float, text_threshold: float) -> list[Detection]:
    """Grounding DINO outputs (normalised cxcywh boxes) -> pixel boxes of each image's original size,
    clipped to the image, degenerate boxes dropped, labels mapped to the prompt phrases."""
    res = processor.post_process_grounded_object_detection(
        out, input_ids, threshold=box_threshold, text_threshold=text_threshold, target_sizes=[tuple(s) for s in sizes]
    )
    dets = []
    for r, (h, w) in zip(res, sizes):
        boxes = r["boxes"].detach().cpu().numpy().reshape(-1, 4).astype(float)
        boxes[:, [0, 2]] = boxes[:, [0, 2]].clip(0, w)
        boxes[:, [1, 3]] = boxes[:, [1, 3]].clip(0, h)
        keep = (boxes[:, 2] - boxes[:, 0] >= 1) & (boxes[:, 3] - boxes[:, 1] >= 1)
        labels = r["text_labels"] if "text_labels" in r else r.get("labels", [])
        dets.append(Detection(boxes[keep], r["scores"].detach().cpu().numpy()[keep].astype(float),
                              [match_phrase(str(l), phrases) for l, k in zip(labels, keep) if k]))
    return dets


def top_detections(d: Detection, nms_iou: float, max_detections: int) -> Detection:
    """Greedy NMS, then at most ``max_detections`` boxes, best first: a frame never holds hundreds of
    openable parts, and each kept box costs a full-resolution mask (an untrained or mis-prompted detector
    can pass all 900 queries)."""
    k = box_nms(d.boxes, d.scores, nms_iou)[: max(0, max_detections)]
    return Detection(d.boxes[k].reshape(-1, 4), d.scores[k], [d.labels[j] for j in k])


def box_nms(boxes: np.ndarray, scores: np.ndarray, iou_threshold: float) -> np.ndarray:
    """Indices kept by greedy non-maximum suppression (Grounded-SAM's demo uses IoU 0.8), best first."""
    order = np.argsort(-scores, kind="stable")
    area = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    keep: list[int] = []
    while len(order):
        i, rest = order[0], order[1:]
        keep.append(int(i))
        wh = (np.minimum(boxes[i, 2:], boxes[rest, 2:]) - np.maximum(boxes[i, :2], boxes[rest, :2])).clip(0)
        inter = wh[:, 0] * wh[:, 1]
        order = rest[inter / np.maximum(area[i] + area[rest] - inter, 1e-9) <= iou_threshold]
    return np.array(keep, dtype=int)


def sam_image_embeddings(sam: Loaded, images: Sequence[np.ndarray], on_device: bool = True) -> tuple[torch.Tensor, dict]:
    """One batched SAM image-encoder forward (the 600M-parameter part for ViT-H)."""
    inputs = preprocess(sam.processor, sam.device, on_device, images=list(images))
    px = to_model({"pixel_values": inputs["pixel_values"]}, sam.device, sam.dtype)["pixel_values"]
    with torch.inference_mode():
        emb = sam.model.get_image_embeddings(px)
    return emb, inputs


def masks_to_original(sam: Loaded, low_res: torch.Tensor, original_size: Sequence[int],
                      reshaped_size: Sequence[int]) -> np.ndarray:
    """SAM low-res logits (1,N,1,h,w) -> bool (N,H,W) at the original image size (unpad, resize, >0).

    Upsampled where the logits are: on a GPU only the boolean masks cross the bus (16 float masks of a
    1920x1440 frame are 177 MB to resize on the CPU), bit-packed (:func:`masks_to_host`: 5.5 MB, not 44)."""
    with torch.inference_mode():
        m = sam.processor.image_processor.post_process_masks(
            low_res.float(), [[int(x) for x in original_size]], [[int(x) for x in reshaped_size]])[0]
        return masks_to_host(m[:, 0])  # already bool: no copy on the CPU


def to_sam_input(coords: np.ndarray, original_size: Sequence[int], reshaped_size: Sequence[int]) -> np.ndarray:
    """Pixel x,y coordinates (…, 2k) of the original image -> SAM's resized input (what SamProcessor
    does to prompts), so prompts need no second pass of image pre-processing."""
    (h, w), (rh, rw) = original_size, reshaped_size
    c = np.asarray(coords, float).copy()
    c[..., 0::2] *= rw / w
    c[..., 1::2] *= rh / h
    return c


def sam_box_masks(sam: Loaded, emb: torch.Tensor, inputs: dict, i: int, boxes: np.ndarray) -> np.ndarray:
    """Masks (N,H,W) of frame ``i`` of an embedded batch for its N boxes (original pixel coordinates)."""
    one = {k: inputs[k][i : i + 1] for k in ("original_sizes", "reshaped_input_sizes")}
    return sam_box_masks_batched(sam, emb[i : i + 1], one, [boxes])[0]


def sam_box_masks_batched(sam: Loaded, emb: torch.Tensor, inputs: dict, boxes: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Masks of every frame of an embedded batch in one decoder call (``boxes[i]``: frame i's (N_i,4), N_i >= 1).

    SAM decodes each box prompt on its own, so frames are padded to the largest N with copies of their first
    box and the copies' masks dropped; one call instead of one per frame saves the decoder's kernel launches."""
    n = max(len(b) for b in boxes)
    prompts = []
    for i, b in enumerate(boxes):
        orig, resh = inputs["original_sizes"][i].tolist(), inputs["reshaped_input_sizes"][i].tolist()
        c = to_sam_input(b, orig, resh)
        prompts.append(np.concatenate([c, np.repeat(c[:1], n - len(c), axis=0)]))
    box_t = torch.as_tensor(np.stack(prompts), device=sam.device, dtype=sam.dtype)
    with torch.inference_mode():
        out = sam.model(image_embeddings=emb[: len(boxes)], input_boxes=box_t, multimask_output=False)
    return [masks_to_original(sam, out.pred_masks[i : i + 1, : len(b)], inputs["original_sizes"][i].tolist(),
                              inputs["reshaped_input_sizes"][i].tolist()) for i, b in enumerate(boxes)]


def sam2_box_masks(sam: Loaded, image: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """SAM 2 box prompts on one image (simplified per-frame path: encoder and decoder together)."""
    prompt = sam.processor(images=[image], input_boxes=[boxes.tolist()], return_tensors="pt")
    feed = {k: (v.to(sam.device, sam.dtype) if v.is_floating_point() else v.to(sam.device))
            for k, v in prompt.items() if k in ("pixel_values", "input_boxes")}
    with torch.inference_mode():
        out = sam.model(**feed, multimask_output=False)
    m = sam.processor.post_process_masks(out.pred_masks.float().cpu(), prompt["original_sizes"])[0]
    return m[:, 0].numpy().astype(bool)


# Queries post-processed per kept detection: NMS (IoU 0.8) rarely removes 3 of every 4 top boxes, so
# top-(4 x max_detections) queries, then NMS, then max_detections gives what NMS over all 900 would.
QUERIES_PER_DETECTION = 4


class GroundedSamSegmenter:
    """TextPromptSegmenter: Grounding DINO (box/text thresholds 0.3/0.25 in the paper) + SAM box prompts."""

    def __init__(self, detector: Loaded, sam: Loaded, box_threshold: float, text_threshold: float, batch_size: int,
                 nms_iou: float = 0.8, max_detections: int = 100, gpu_preprocess: bool = True) -> None:
        self.detector, self.sam, self.nms_iou, self.max_detections = detector, sam, nms_iou, max_detections
        self.box_threshold, self.text_threshold, self.batch_size = box_threshold, text_threshold, batch_size
        self.gpu_preprocess = gpu_preprocess

    def groups(self, phrases: Sequence[str]) -> list[list[str]]:
        """Phrases per detector prompt (one prompt unless they exceed the model's text length)."""
        tok = getattr(self.detector.processor, "tokenizer", None)
        max_len = int(getattr(self.detector.model.config, "max_text_len", 256))
        return phrase_groups(phrases, tok, max_len) if tok is not None else [list(phrases)]

    def segment(self, frames: Sequence[Frame], images: Sequence[np.ndarray], phrases: Sequence[str]) -> list[list[Mask2D]]:
        if len(frames) != len(images):
            raise ValueError(f"{len(frames)} frames but {len(images)} images")
        phrases = [p for p in phrases if p.strip()]
        if not phrases:
            return [[] for _ in frames]
        with worker_stream(self.detector.device):  # worker threads do not wait for each other's GPU work
            return self._segment(frames, images, phrases)

    def _segment(self, frames: Sequence[Frame], images: Sequence[np.ndarray], phrases: Sequence[str]) -> list[list[Mask2D]]:
        out: list[list[Mask2D]] = []
        for s in range(0, len(frames), self.batch_size):
            fr, im = list(frames[s : s + self.batch_size]), list(images[s : s + self.batch_size])
            dets = [Detection(np.zeros((0, 4)), np.zeros(0), []) for _ in im]
            for group in self.groups(phrases):
                for d, g in zip(dets, detect(self.detector, im, group, self.box_threshold, self.text_threshold,
                                             self.gpu_preprocess, QUERIES_PER_DETECTION * self.max_detections)):
                    d.boxes, d.scores, d.labels = np.concatenate([d.boxes, g.boxes]), np.concatenate([d.scores, g.scores]), d.labels + g.labels
            dets = [top_detections(d, self.nms_iou, self.max_detections) for d in dets]
            want = [i for i, d in enumerate(dets) if len(d.boxes)]
            emb = inputs = None
            if want and not is_sam2(self.sam):
                emb, inputs = sam_image_embeddings(self.sam, [im[i] for i in want], self.gpu_preprocess)
            decoded = (sam_box_masks_batched(self.sam, emb, inputs, [dets[i].boxes for i in want])
                       if want and not is_sam2(self.sam) else [])
            for i, (f, image, d) in enumerate(zip(fr, im, dets)):
                if not len(d.boxes):
                    out.append([])
                    continue
                if is_sam2(self.sam):
                    masks = sam2_box_masks(self.sam, image, d.boxes)
                else:
                    masks = decoded[want.index(i)]
                out.append([
                    Mask2D(frame_id=f.frame_id, label=lab, score=float(sc), mask=m, box=tuple(float(x) for x in b))
                    for m, b, sc, lab in zip(masks, d.boxes, d.scores, d.labels) if m.any()
                ])
        return out


class SamPointSegmenter:
    """PointPromptSegmenter: SAM with positive/negative points; the best of SAM's 3 masks by predicted IoU.

    The last frame's image embedding is kept, so re-segmenting several objects in one view encodes it once.
    """

    def __init__(self, sam: Loaded) -> None:
        self.sam = sam
        self._last: tuple[str, tuple[int, ...], torch.Tensor, dict] | None = None

    def _embed(self, frame: Frame, image: np.ndarray) -> tuple[torch.Tensor, dict]:
        key = (frame.frame_id, image.shape)
        if self._last is None or self._last[:2] != key:
            emb, inputs = sam_image_embeddings(self.sam, [image])
            self._last = (*key, emb, inputs)
        return self._last[2], self._last[3]

    def segment_points(self, frame: Frame, image: np.ndarray, points: np.ndarray, labels: np.ndarray) -> Mask2D:
        points = np.asarray(points, float).reshape(-1, 2)
        labels = np.asarray(labels, int).reshape(-1)
        if len(points) == 0 or len(points) != len(labels):
            raise ValueError(f"need N>0 points with N labels, got {len(points)} points and {len(labels)} labels")
        with torch.inference_mode():
            if is_sam2(self.sam):
                prompt = self.sam.processor(images=[image], input_points=[[points.tolist()]], input_labels=[[labels.tolist()]],
                                            return_tensors="pt")
                out = self.sam.model(pixel_values=prompt["pixel_values"].to(self.sam.device, self.sam.dtype),
                                     input_points=prompt["input_points"].to(self.sam.device, self.sam.dtype),
                                     input_labels=prompt["input_labels"].to(self.sam.device), multimask_output=True)
            else:
                emb, inputs = self._embed(frame, image)
                orig, resh = inputs["original_sizes"][0].tolist(), inputs["reshaped_input_sizes"][0].tolist()
                pts = torch.as_tensor(to_sam_input(points, orig, resh)[None, None], device=self.sam.device, dtype=self.sam.dtype)
                lab = torch.as_tensor(labels[None, None], device=self.sam.device)
                out = self.sam.model(image_embeddings=emb, input_points=pts, input_labels=lab, multimask_output=True)
        best = int(out.iou_scores[0, 0].float().argmax())
        low = out.pred_masks[:, :, best : best + 1]
        if is_sam2(self.sam):
            mask = self.sam.processor.post_process_masks(low.float().cpu(), prompt["original_sizes"])[0][0, 0].numpy()
        else:
            mask = masks_to_original(self.sam, low, orig, resh)[0]
        ys, xs = np.nonzero(mask)
        box = (float(xs.min()), float(ys.min()), float(xs.max() + 1), float(ys.max() + 1)) if len(xs) else None
        return Mask2D(frame_id=frame.frame_id, label="openable", score=float(out.iou_scores[0, 0, best]), mask=mask.astype(bool), box=box)
