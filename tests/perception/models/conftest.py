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
from react3d_models.random_checkpoints import save_random_checkpoints  # noqa: E402


def make_frame(frame_id: str, h: int, w: int) -> Frame:
    return Frame(frame_id=frame_id, rgb=ImageRef(path=Path(f"/nonexistent/{frame_id}.png"), kind="png"),
                 intrinsics=Intrinsics(fx=w, fy=w, cx=w / 2, cy=h / 2, width=w, height=h), pose=np.eye(4))


def make_image(h: int, w: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    img = np.full((h, w, 3), 200, np.uint8)
    img[h // 4 : 3 * h // 4, w // 4 : 3 * w // 4] = rng.integers(0, 120, 3, dtype=np.uint8)
    return img


@pytest.fixture(scope="session")
def tiny_models(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Folders with save_pretrained() tiny detector / SAM / CLIP (a few layers, 16-32 dims)."""
    return save_random_checkpoints(tmp_path_factory.mktemp("tiny_models"), "tiny")


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
