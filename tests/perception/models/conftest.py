"""Tiny randomly initialised Grounding DINO / SAM / CLIP checkpoints saved to disk, fake HTTP servers.

Nothing is downloaded: HF_HUB_OFFLINE=1, tokenizers are built from hand-written vocabularies, and
the adapters load the tiny checkpoints through the same ``from_pretrained`` path as real ones.
"""

from __future__ import annotations

import json
import os
import threading
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

os.environ["HF_HUB_OFFLINE"] = "1"
os.environ["TRANSFORMERS_OFFLINE"] = "1"

import numpy as np  # noqa: E402
import pytest  # noqa: E402

torch = pytest.importorskip("torch")
transformers = pytest.importorskip("transformers")

# One intra-op thread: the tiny models gain nothing from more, and on a shared 2-core box torch's
# spinning worker threads made each forward 10-50x slower under load.
torch.set_num_threads(1)

from react3d_core.data.frames import Frame, ImageRef, Intrinsics  # noqa: E402

WORDS = "[PAD] [UNK] [CLS] [SEP] [MASK] . a photo of cabinet door drawer oven wardrobe table chair floor".split()


def make_frame(frame_id: str, h: int, w: int) -> Frame:
    return Frame(frame_id=frame_id, rgb=ImageRef(path=Path(f"/nonexistent/{frame_id}.png"), kind="png"),
                 intrinsics=Intrinsics(fx=w, fy=w, cx=w / 2, cy=h / 2, width=w, height=h), pose=np.eye(4))


def make_image(h: int, w: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    img = np.full((h, w, 3), 200, np.uint8)
    img[h // 4 : 3 * h // 4, w // 4 : 3 * w // 4] = rng.integers(0, 120, 3, dtype=np.uint8)
    return img


def _bert_tokenizer() -> Any:
    return transformers.BertTokenizer(vocab={w: i for i, w in enumerate(WORDS)})


@pytest.fixture(scope="session")
def tiny_models(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Folders with save_pretrained() tiny detector / SAM / CLIP (a few layers, 16-32 dims)."""
    root = tmp_path_factory.mktemp("tiny_models")
    torch.manual_seed(0)
    tf = transformers
    # Grounding DINO: Swin backbone 64 px, 1-layer BERT text tower, 2 decoder layers (1 breaks weight tying).
    det = root / "gdino"
    det.mkdir()
    tok = _bert_tokenizer()
    cfg = tf.GroundingDinoConfig(
        backbone_config=tf.SwinConfig(image_size=64, patch_size=4, embed_dim=16, depths=[1, 1, 1, 1], num_heads=[1, 1, 1, 1],
                                      window_size=4, out_indices=[2, 3, 4]),
        text_config=tf.BertConfig(vocab_size=len(WORDS), hidden_size=32, num_hidden_layers=1, num_attention_heads=2,
                                  intermediate_size=32, max_position_embeddings=64),
        d_model=32, encoder_layers=1, decoder_layers=2, encoder_ffn_dim=32, decoder_ffn_dim=32, encoder_attention_heads=2,
        decoder_attention_heads=2, num_queries=20, num_feature_levels=4, encoder_n_points=2, decoder_n_points=2, max_text_len=32)
    tf.GroundingDinoForObjectDetection(cfg).save_pretrained(det)
    ip = tf.GroundingDinoImageProcessor(size={"shortest_edge": 64, "longest_edge": 96})
    tf.GroundingDinoProcessor(image_processor=ip, tokenizer=tok).save_pretrained(det)
    # SAM: 64 px input, 8 px patches -> 8x8 embeddings, 16 channels.
    sam = root / "sam"
    scfg = tf.SamConfig(
        vision_config=dict(hidden_size=32, num_hidden_layers=1, num_attention_heads=2, image_size=64, patch_size=8,
                           output_channels=16, mlp_dim=32, global_attn_indexes=[0], window_size=4, num_pos_feats=8),
        prompt_encoder_config=dict(hidden_size=16, image_size=64, patch_size=8, mask_input_channels=4),
        mask_decoder_config=dict(hidden_size=16, num_hidden_layers=1, num_attention_heads=2, mlp_dim=32, iou_head_hidden_dim=16))
    tf.SamModel(scfg).save_pretrained(sam)
    tf.SamProcessor(image_processor=tf.SamImageProcessor(size={"longest_edge": 64}, pad_size={"height": 64, "width": 64},
                                                          mask_size={"longest_edge": 32})).save_pretrained(sam)
    # CLIP: 32 px images, 1-layer towers, the same word-level vocabulary.
    clip = root / "clip"
    clip.mkdir()
    ctok = _bert_tokenizer()
    ccfg = tf.CLIPConfig(
        text_config=dict(vocab_size=len(WORDS), hidden_size=16, intermediate_size=32, num_hidden_layers=1, num_attention_heads=2,
                         max_position_embeddings=32, bos_token_id=2, eos_token_id=3, pad_token_id=0),
        vision_config=dict(hidden_size=16, intermediate_size=32, num_hidden_layers=1, num_attention_heads=2, image_size=32, patch_size=8),
        projection_dim=16)
    tf.CLIPModel(ccfg).save_pretrained(clip)
    tf.CLIPProcessor(image_processor=tf.CLIPImageProcessor(size={"shortest_edge": 32}, crop_size={"height": 32, "width": 32}),
                     tokenizer=ctok).save_pretrained(clip)
    return {"detector": det, "sam": sam, "clip": clip}


class FakeServer:
    """An HTTP server on 127.0.0.1 answering POSTs with a scripted handler; records request bodies."""

    def __init__(self, handler: Callable[[int, dict], tuple[int, bytes, float]]) -> None:
        self.requests: list[dict] = []
        outer = self

        class H(BaseHTTPRequestHandler):
            def do_POST(self) -> None:  # noqa: N802 - http.server API
                body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
                outer.requests.append({"path": self.path, "body": body})
                code, payload, delay = handler(len(outer.requests) - 1, body)
                if delay:
                    threading.Event().wait(delay)
                try:
                    self.send_response(code)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(payload)))
                    self.end_headers()
                    self.wfile.write(payload)
                except (BrokenPipeError, ConnectionResetError):
                    pass

            def log_message(self, *args: Any) -> None:
                pass

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), H)
        self.httpd.daemon_threads = True
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def fake_server() -> Iterator[Callable[..., FakeServer]]:
    servers: list[FakeServer] = []

    def start(handler: Callable[[int, dict], tuple[int, bytes, float]]) -> FakeServer:
        servers.append(FakeServer(handler))
        return servers[-1]

    yield start
    for s in servers:
        s.close()


@pytest.fixture(name="make_frame")
def make_frame_fixture() -> Callable[[str, int, int], Frame]:
    """Factory: ``make_frame(frame_id, h, w)`` with identity pose and a plausible pinhole."""
    return make_frame


@pytest.fixture(name="make_image")
def make_image_fixture() -> Callable[[int, int, int], np.ndarray]:
    """Factory: ``make_image(h, w, seed)``: grey frame with one coloured rectangle."""
    return make_image
