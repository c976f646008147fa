"""OPDMulti through a JSON contract (docs/perception_models.md): the user runs OPDMulti in its own
environment behind an HTTP endpoint (POST) or a command (JSON on stdin, JSON on stdout); we send
the frames and turn its predictions into ArticulationPrediction (camera frame, OpenCV axes).

Request:  {"version": 1, "frames": [{"frame_id", "width", "height", "K": 3x3, "image_png_base64"}]}
Response: {"predictions": [{"frame_id", "joint_type": "revolute"|"prismatic"|"rotation"|"translation",
           "axis": [x,y,z], "origin": [x,y,z] | null, "origin_px": [u,v] | null, "score",
           "mask_png_base64" | "box": [x0,y0,x1,y1]}]}
"""

from __future__ import annotations

import base64
import json
import logging
import shlex
import subprocess
import time
import urllib.error
import urllib.request
from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np

from react3d_core.data.frames import Frame
from react3d_core.data.masks import ArticulationPrediction
from react3d_core.errors import StageError

log = logging.getLogger(__name__)

_TYPES = {"revolute": "revolute", "rotation": "revolute", "prismatic": "prismatic", "translation": "prismatic"}


def encode_png(image: np.ndarray) -> str:
    """RGB (or single-channel) uint8 image -> base64 PNG."""
    img = image if image.ndim == 2 else cv2.cvtColor(np.ascontiguousarray(image[..., :3]), cv2.COLOR_RGB2BGR)
    ok, buf = cv2.imencode(".png", img)
    if not ok:
        raise ValueError("PNG encoding failed")
    return base64.b64encode(buf.tobytes()).decode()


def decode_mask(b64: str, height: int, width: int) -> np.ndarray:
    """Base64 PNG (any size, nonzero = part) -> bool mask at (height, width), nearest-neighbour resize."""
    m = cv2.imdecode(np.frombuffer(base64.b64decode(b64), np.uint8), cv2.IMREAD_GRAYSCALE)
    if m is None:
        raise ValueError("mask is not a PNG")
    if m.shape != (height, width):
        m = cv2.resize(m, (width, height), interpolation=cv2.INTER_NEAREST)
    return m > 0


def build_request(frames: Sequence[Frame], images: Sequence[np.ndarray]) -> dict[str, Any]:
    """The request document for a batch of frames (images at their stored RGB resolution)."""
    return {"version": 1, "frames": [
        {"frame_id": f.frame_id, "width": int(im.shape[1]), "height": int(im.shape[0]),
         "K": f.intrinsics.scaled(int(im.shape[1]), int(im.shape[0])).K.tolist(), "image_png_base64": encode_png(im)}
        for f, im in zip(frames, images)]}


def _vec(v: Any, n: int) -> tuple[float, ...] | None:
    if v is None:
        return None
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"expected {n} finite numbers, got {v!r}")
    return tuple(float(x) for x in a)


def parse_prediction(p: dict[str, Any], sizes: dict[str, tuple[int, int]]) -> ArticulationPrediction:
    """One prediction dict -> ArticulationPrediction; raises ValueError naming the bad field."""
    fid = str(p["frame_id"])
    if fid not in sizes:
        raise ValueError(f"unknown frame_id {fid!r}")
    h, w = sizes[fid]
    jt = _TYPES.get(str(p.get("joint_type", "")).lower())
    if jt is None:
        raise ValueError(f"joint_type {p.get('joint_type')!r} is not revolute/prismatic")
    axis = np.asarray(_vec(p.get("axis"), 3), float)
    norm = float(np.linalg.norm(axis))
    if norm < 1e-9:
        raise ValueError("axis has zero length")
    if p.get("mask_png_base64"):
        mask = decode_mask(p["mask_png_base64"], h, w)
    elif p.get("box") is not None:
        x0, y0, x1, y1 = _vec(p["box"], 4)
        mask = np.zeros((h, w), bool)
        mask[max(int(round(y0)), 0) : max(int(round(y1)), 0), max(int(round(x0)), 0) : max(int(round(x1)), 0)] = True
    else:
        raise ValueError("prediction has neither mask_png_base64 nor box")
    return ArticulationPrediction(
        frame_id=fid, mask=mask, joint_type=jt, axis_cam=tuple(float(x) for x in axis / norm),
        origin_cam=_vec(p.get("origin"), 3), origin_px=_vec(p.get("origin_px"), 2), score=float(p.get("score", 1.0)),
    )


def parse_response(doc: Any, frames: Sequence[Frame], images: Sequence[np.ndarray], min_score: float) -> list[list[ArticulationPrediction]]:
    """Response document -> predictions grouped per frame; malformed single predictions are skipped with a warning."""
    if not isinstance(doc, dict) or not isinstance(doc.get("predictions"), list):
        raise StageError("OPDMulti reply is not a JSON object with a 'predictions' list")
    sizes = {f.frame_id: im.shape[:2] for f, im in zip(frames, images)}
    by_frame: dict[str, list[ArticulationPrediction]] = {f.frame_id: [] for f in frames}
    for i, p in enumerate(doc["predictions"]):
        try:
            pred = parse_prediction(p, sizes)
        except (ValueError, KeyError, TypeError) as exc:
            log.warning("OPDMulti prediction %d skipped: %s", i, exc)
            continue
        if pred.score >= min_score and pred.mask.any():
            by_frame[pred.frame_id].append(pred)
    return [by_frame[f.frame_id] for f in frames]


def prediction_to_world(pred: ArticulationPrediction, frame: Frame) -> tuple[np.ndarray, np.ndarray | None]:
    """(axis, origin) of a camera-frame prediction in world coordinates: axis rotated by the pose,
    origin transformed as a point (None when OPDMulti gave only a pixel; depth lifts that later)."""
    c2w = frame.c2w
    axis = c2w[:3, :3] @ np.asarray(pred.axis_cam, float)
    origin = None if pred.origin_cam is None else c2w[:3, :3] @ np.asarray(pred.origin_cam, float) + c2w[:3, 3]
    return axis / np.linalg.norm(axis), origin


class OPDMultiClient:
    """ArticulationPredictor over the JSON contract: 'http(s)://…' is POSTed to, anything else is a command."""

    def __init__(self, endpoint: str, timeout_s: float, min_score: float, retries: int = 2, backoff_s: float = 1.0,
                 batch_size: int = 8, api_key: str | None = None) -> None:
        self.endpoint, self.timeout_s, self.min_score = endpoint, timeout_s, min_score
        self.retries, self.backoff_s, self.batch_size = retries, backoff_s, batch_size
        self.is_http = endpoint.startswith(("http://", "https://"))
        self._headers = {"Content-Type": "application/json"}
        if api_key:  # from the environment or a Secret block, never from the config (it is recorded)
            self._headers["Authorization"] = f"Bearer {api_key}"

    def _call(self, payload: bytes) -> Any:
        last: Exception | None = None
        for attempt in range(self.retries + 1):
            try:
                if self.is_http:
                    req = urllib.request.Request(self.endpoint, data=payload, headers=self._headers, method="POST")
                    with urllib.request.urlopen(req, timeout=self.timeout_s) as resp:
                        return json.loads(resp.read())
                proc = subprocess.run(shlex.split(self.endpoint), input=payload, capture_output=True, timeout=self.timeout_s, check=False)
                if proc.returncode != 0:
                    raise StageError(f"OPDMulti command {self.endpoint!r} exited {proc.returncode}: "
                                     f"{proc.stderr.decode(errors='replace').strip().splitlines()[-1:] or ''}")
                return json.loads(proc.stdout)
            except urllib.error.HTTPError as exc:
                last = exc
                if exc.code < 500 and exc.code != 429:
                    break
            except (urllib.error.URLError, TimeoutError, ConnectionError, subprocess.TimeoutExpired, json.JSONDecodeError) as exc:
                last = exc
            except FileNotFoundError:
                raise StageError(f"OPDMulti command not found: {self.endpoint!r}") from None
            if attempt < self.retries:
                time.sleep(self.backoff_s * 2**attempt)
        raise StageError(f"OPDMulti at {self.endpoint!r} failed: {type(last).__name__}: {last}")

    def predict(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[ArticulationPrediction]]:
        if len(frames) != len(images):
            raise ValueError(f"{len(frames)} frames but {len(images)} images")
        out: list[list[ArticulationPrediction]] = []
        for s in range(0, len(frames), self.batch_size):
            fr, im = list(frames[s : s + self.batch_size]), list(images[s : s + self.batch_size])
            doc = self._call(json.dumps(build_request(fr, im)).encode())
            out.extend(parse_response(doc, fr, im, self.min_score))
        return out


class NoArticulationPredictor:
    """Used when no OPDMulti endpoint is configured: no per-view predictions, so the articulation
    stage relies on its own geometric estimate. Says so once, in the log."""

    def __init__(self) -> None:
        self._warned = False

    def predict(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[ArticulationPrediction]]:
        if not self._warned:
            log.warning("perception.models.articulation_endpoint is not set: no OPDMulti predictions (see docs/perception_models.md)")
            self._warned = True
        return [[] for _ in frames]
