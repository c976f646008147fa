"""Grounded-SAM / SAM adapters on tiny random checkpoints: batching, sizes, coordinates, thresholds."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from react3d_models.grounded_sam import (GroundedSamSegmenter, SamPointSegmenter, box_nms, detect, detections_from_outputs,
                                       detector_prompt, masks_to_original, match_phrase, phrase_groups,
                                       to_sam_input)
from react3d_models.loaders import load_detector, load_sam

SIZES = [(48, 64), (96, 128), (60, 80)]


@pytest.fixture(scope="module")
def loaded(tiny_models):
    cpu = torch.device("cpu")
    return load_detector(str(tiny_models["detector"]), cpu, torch.float32), load_sam(str(tiny_models["sam"]), cpu, torch.float32)


def test_detector_prompt_and_phrase_matching():
    assert detector_prompt(["Cabinet door", "door.", " "]) == "cabinet door. door."
    assert match_phrase("cabinet", ["door", "cabinet door"]) == "cabinet door"
    assert match_phrase("[CLS] door [SEP]", ["oven door", "door"]) == "door"  # exact beats superset
    assert match_phrase("oven", ["oven door", "door"]) == "oven door"
    assert match_phrase("[UNK]", ["door"]) == "openable"


def test_segment_batches_and_returns_masks_at_frame_size(loaded, make_frame, make_image):
    det, sam = loaded
    frames = [make_frame(f"f{i}", h, w) for i, (h, w) in enumerate(SIZES)]
    images = [make_image(h, w, i) for i, (h, w) in enumerate(SIZES)]
    seg = GroundedSamSegmenter(det, sam, box_threshold=0.0, text_threshold=0.0, batch_size=2)
    out = seg.segment(frames, images, ["cabinet door", "door"])
    assert len(out) == 3
    for f, (h, w), masks in zip(frames, SIZES, out):
        assert masks, "threshold 0 must keep the detector's queries"
        for m in masks:
            assert m.frame_id == f.frame_id and m.mask.shape == (h, w) and m.mask.dtype == bool
            x0, y0, x1, y1 = m.box
            assert 0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h
            assert m.label in ("cabinet door", "door")
    # batching must not change results: one frame at a time gives the same boxes
    single = GroundedSamSegmenter(det, sam, 0.0, 0.0, batch_size=1).segment(frames[1:2], images[1:2], ["cabinet door", "door"])
    got = sorted(m.box for m in out[1])
    ref = sorted(m.box for m in single[0])
    np.testing.assert_allclose(np.array(got), np.array(ref), atol=0.5)


def test_thresholds_are_applied(loaded, make_frame, make_image):
    det, sam = loaded
    im = [make_image(60, 80, 0)]
    all_dets = detect(det, im, ["door"], 0.0, 0.0)[0]
    strict = detect(det, im, ["door"], 0.3, 0.25)[0]
    assert (strict.scores >= 0.3).all()
    assert len(strict.boxes) == int((all_dets.scores >= 0.3).sum())
    assert GroundedSamSegmenter(det, sam, 1.0, 1.0, 4).segment([make_frame("a", 60, 80)], im, ["door"]) == [[]]
    assert GroundedSamSegmenter(det, sam, 0.0, 0.0, 4).segment([make_frame("a", 60, 80)], im, []) == [[]]


def test_low_res_mask_maps_back_to_rescaled_image(loaded):
    """Hand-computed: a 128x96 image is resized by 0.5 to 64x48 inside SAM's 64x64 padded input; the
    32x32 low-res mask is 2 px/cell there, so cells rows 4..11, cols 8..15 -> padded px rows 8..23,
    cols 16..31 -> original px rows 16..47, cols 32..63."""
    _, sam = loaded
    low = torch.full((1, 1, 1, 32, 32), -10.0)
    low[..., 4:12, 8:16] = 10.0
    m = masks_to_original(sam, low, (96, 128), (48, 64))[0]
    expect = np.zeros((96, 128), bool)
    expect[16:48, 32:64] = True
    assert m.shape == (96, 128)
    iou = (m & expect).sum() / (m | expect).sum()
    assert iou > 0.9


def test_box_prompt_is_rescaled_like_the_image(loaded, make_frame, make_image):
    """A box (x0,y0,x1,y1)=(20,10,100,60) on a 128x96 image is 0.5x in SAM's 64-px input."""
    _, sam = loaded
    p = sam.processor(images=[make_image(96, 128, 0)], input_boxes=[[[20, 10, 100, 60]]], return_tensors="pt")
    np.testing.assert_allclose(p["input_boxes"][0, 0].numpy(), [10, 5, 50, 30])
    ours = to_sam_input(np.array([[20, 10, 100, 60]]), (96, 128), p["reshaped_input_sizes"][0].tolist())
    np.testing.assert_allclose(ours, [[10, 5, 50, 30]])  # our prompt scaling == the processor's
    pts = sam.processor(images=[make_image(60, 80, 0)], input_points=[[[70, 50], [3, 1]]], return_tensors="pt")
    np.testing.assert_allclose(to_sam_input(np.array([[70, 50], [3, 1]]), (60, 80), pts["reshaped_input_sizes"][0].tolist()),
                               pts["input_points"][0, 0].numpy(), atol=1e-6)


def test_point_segmenter_reuses_embedding(loaded, make_frame, make_image):
    _, sam = loaded
    ps = SamPointSegmenter(sam)
    f, im = make_frame("p", 96, 128), make_image(96, 128, 1)
    m1 = ps.segment_points(f, im, np.array([[60, 40], [5, 5]]), np.array([1, 0]))
    emb = ps._last[2]
    m2 = ps.segment_points(f, im, np.array([[30, 30]]), np.array([1]))
    assert ps._last[2] is emb
    assert m1.mask.shape == m2.mask.shape == (96, 128) and 0.0 <= m1.score
    with pytest.raises(ValueError):
        ps.segment_points(f, im, np.zeros((2, 2)), np.array([1]))


def test_known_boxes_map_to_original_pixels(loaded):
    """Hand-computed: on a 128x96 image, normalised cxcywh (0.5,0.5,0.5,0.5) -> (32,24,96,72) px;
    (0.95,0.5,0.3,0.2) -> x 102.4..140.8 clipped to 128, y 38.4..57.6; a query with all logits -10
    (score sigmoid(-10) < 0.3) is dropped. Token logits pick the phrase: 'cabinet door' vs 'door'."""
    from transformers.models.grounding_dino.modeling_grounding_dino import GroundingDinoObjectDetectionOutput

    det, _ = loaded
    ids = det.processor(text=detector_prompt(["cabinet door", "door"]), return_tensors="pt")["input_ids"]
    toks = det.processor.tokenizer.convert_ids_to_tokens(ids[0])
    assert toks == ["[CLS]", "cabinet", "door", ".", "door", ".", "[SEP]"]
    logits = torch.full((1, 3, ids.shape[1]), -10.0)
    logits[0, 0, 1:3] = 10.0  # 'cabinet door'
    logits[0, 1, 4] = 10.0  # 'door'
    boxes = torch.tensor([[[0.5, 0.5, 0.5, 0.5], [0.95, 0.5, 0.3, 0.2], [0.5, 0.5, 0.1, 0.1]]])
    out = GroundingDinoObjectDetectionOutput(logits=logits, pred_boxes=boxes)
    d = detections_from_outputs(det.processor, out, ids, [(96, 128)], ["cabinet door", "door"], 0.3, 0.25)[0]
    np.testing.assert_allclose(d.boxes, [[32, 24, 96, 72], [102.4, 38.4, 128, 57.6]], atol=1e-4)
    assert d.labels == ["cabinet door", "door"]
    np.testing.assert_allclose(d.scores, [1 / (1 + np.exp(-10))] * 2, rtol=1e-6)


def test_long_prompts_are_split_to_fit_the_text_length(loaded, make_frame, make_image):
    """'cabinet door.' is 3 tokens; with [CLS]/[SEP] a prompt of k such phrases is 3k+2 tokens, so at
    most 3 fit in 11 tokens: 7 phrases -> groups of 3, 3, 1. The tiny model's limit is 32 tokens."""
    det, sam = loaded
    tok = det.processor.tokenizer
    phrases = ["cabinet door"] * 7
    assert [len(g) for g in phrase_groups(phrases, tok, 11)] == [3, 3, 1]
    assert phrase_groups(["door"], tok, 11) == [["door"]]
    seg = GroundedSamSegmenter(det, sam, 0.0, 0.0, batch_size=2)
    many = ["cabinet door", "drawer door", "oven door", "wardrobe door", "door", "table door", "chair door",
            "floor door", "cabinet drawer", "oven drawer", "wardrobe drawer"]  # 33+ tokens > 32
    assert len(seg.groups(many)) == 2
    out = GroundedSamSegmenter(det, sam, 0.0, 0.0, batch_size=2, nms_iou=1.0).segment(
        [make_frame("a", 60, 80)], [make_image(60, 80, 0)], many)
    assert len(out[0]) > 20  # 20 queries per prompt, two prompts (NMS off)


def test_box_nms_hand_computed():
    """Boxes 0 and 1 overlap with IoU 81/119 = 0.68 (9x9 inside 10x10 shifted): suppressed at 0.5, kept at 0.8;
    box 2 is disjoint. Order is by score."""
    boxes = np.array([[0, 0, 10, 10], [1, 1, 11, 11], [20, 20, 30, 30]], float)
    scores = np.array([0.5, 0.9, 0.7])
    assert box_nms(boxes, scores, 0.5).tolist() == [1, 2]
    assert box_nms(boxes, scores, 0.8).tolist() == [1, 2, 0]
    assert box_nms(np.zeros((0, 4)), np.zeros(0), 0.8).tolist() == []


def test_top_queries_keeps_the_best_scored_queries_hand_computed():
    from react3d_models.grounded_sam import top_queries

    # 1 image, 4 queries, 2 tokens: best token logits 0.1, 2.0, -1.0, 1.5 -> keep queries 1 and 3, best first
    logits = torch.tensor([[[0.1, -3.0], [2.0, 0.0], [-1.0, -2.0], [-5.0, 1.5]]])
    boxes = torch.arange(16, dtype=torch.float32).reshape(1, 4, 4)
    lg, bx = top_queries(logits, boxes, 2)
    assert lg.tolist() == [[[2.0, 0.0], [-5.0, 1.5]]]
    assert bx.tolist() == [[[4.0, 5.0, 6.0, 7.0], [12.0, 13.0, 14.0, 15.0]]]
    assert top_queries(logits, boxes, 0)[0] is logits and top_queries(logits, boxes, 4)[1] is boxes


def test_batched_decoder_equals_one_call_per_frame(loaded, make_image):
    """Frames with 1 and 3 boxes decoded together (padded) give the masks of one decoder call per frame."""
    from react3d_models.grounded_sam import sam_box_masks, sam_box_masks_batched, sam_image_embeddings

    _, sam = loaded
    images = [make_image(60, 80, 0), make_image(60, 80, 1)]
    emb, inputs = sam_image_embeddings(sam, images)
    boxes = [np.array([[10.0, 5.0, 50.0, 40.0]]), np.array([[0.0, 0.0, 30.0, 30.0], [20.0, 10.0, 70.0, 55.0], [5.0, 5.0, 15.0, 15.0]])]
    together = sam_box_masks_batched(sam, emb, inputs, boxes)
    apart = [sam_box_masks(sam, emb, inputs, i, b) for i, b in enumerate(boxes)]
    assert [t.shape for t in together] == [(1, 60, 80), (3, 60, 80)]
    for t, a in zip(together, apart):
        assert (t == a).mean() > 0.999
