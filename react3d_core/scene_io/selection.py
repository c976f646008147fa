"""Frame selection (FrameSelectionConfig): keyframes by what the views add (default), or an explicit stride.

Keyframes: a frame is kept when the camera moved or turned enough since the last kept frame (a static
or slowly drifting camera adds nothing) *and*, when a rasterizer of the scan is given, when enough of
what it sees is surface not yet covered by ``coverage_target_views`` kept frames (a camera walking the
same path twice adds nothing the second time). Coverage is counted on the scan points a low-resolution
face-id/depth buffer hits, binned in voxels, so it does not depend on how finely the mesh is
triangulated. Both rules are in metres, degrees and surface, not frame counts, so a 60 fps video and a
sparse capture of the same walk give similar selections. Then an even cap.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ..camera import unproject
from ..config.scene_io import FrameSelectionConfig
from ..data.frames import Frame
from ..raster import Rasterizer

_HASH_BITS = 22  # 4 M counters (16 MB); collisions only merge far-apart voxels' counts
SELECTION_VERSION = "1"  # bump when the selection rules change: memoised selections are then recomputed


class SelectionMemo(Protocol):
    """Where keyframe selections are remembered between runs (``tasks.scene`` keeps them in the cache):
    the coverage rule renders every candidate frame, which a re-run of the same capture need not redo."""

    def get(self, key: str) -> dict[str, Any] | None: ...

    def put(self, key: str, value: dict[str, Any]) -> None: ...


@dataclass(frozen=True)
class FrameSelection:
    """The kept frames and a one-line account of why (printed by ``react3d convert``)."""

    frames: list[Frame]
    total: int
    reason: str
    skipped_motion: int = 0
    skipped_coverage: int = 0
    dropped_by_cap: int = 0


def _rotation_deg(Ra: np.ndarray, Rb: np.ndarray) -> float:
    c = (np.trace(Ra.T @ Rb) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def _even_cap(items: list[Frame], cap: int | None) -> list[Frame]:
    if cap is None or len(items) <= cap:
        return items
    idx = np.unique(np.round(np.linspace(0, len(items) - 1, cap)).astype(int))
    return [items[i] for i in idx]


def _voxel_hashes(rast: Rasterizer, frame: Frame, width: int, voxel_m: float) -> np.ndarray:
    """Hashed voxel ids of the scan points this frame sees, from a ``width``-pixel-wide depth buffer."""
    intr = frame.intrinsics
    intr = intr.scaled(width, max(1, round(intr.height * width / intr.width)))
    res = rast.render(intr.K, frame.c2w, intr.width, intr.height, frame.frame_id)
    pts = unproject(res.depth, intr.K, frame.c2w)[res.depth > 0]
    if not len(pts):
        return np.zeros(0, np.int64)
    ijk = np.floor(pts / voxel_m).astype(np.int64)
    h = (ijk[:, 0] * 73856093) ^ (ijk[:, 1] * 19349663) ^ (ijk[:, 2] * 83492791)
    return np.unique(h & ((1 << _HASH_BITS) - 1))


def _keyframes(frames: list[Frame], cfg: FrameSelectionConfig, rasterizer: Rasterizer | None) -> FrameSelection:
    n = len(frames)
    poses = np.stack([f.c2w for f in frames])
    use_cov = rasterizer is not None and cfg.coverage_width > 0
    counts = np.zeros(1 << _HASH_BITS if use_cov else 0, np.int32)  # kept frames that saw each voxel (hashed)
    kept = [0]
    if use_cov:
        counts[_voxel_hashes(rasterizer, frames[0], cfg.coverage_width, cfg.coverage_voxel_m)] += 1
    last = poses[0]
    skip_motion = skip_cov = 0
    for i in range(1, n):
        cur = poses[i]
        moved = float(np.linalg.norm(cur[:3, 3] - last[:3, 3])) >= cfg.keyframe_translation_m
        if not moved and _rotation_deg(last[:3, :3], cur[:3, :3]) < cfg.keyframe_rotation_deg:
            skip_motion += 1
            continue
        if use_cov:
            vox = _voxel_hashes(rasterizer, frames[i], cfg.coverage_width, cfg.coverage_voxel_m)
            new = float(np.mean(counts[vox] < cfg.coverage_target_views)) if vox.size else 0.0
            if new < cfg.coverage_min_new:
                skip_cov += 1
                continue
            counts[vox] += 1
        kept.append(i)
        last = cur
    cap = cfg.keyframe_cap if cfg.max_frames is None else min(cfg.keyframe_cap, cfg.max_frames)
    out = _even_cap([frames[i] for i in kept], cap)
    rule = (f"motion (>= {cfg.keyframe_translation_m:g} m or >= {cfg.keyframe_rotation_deg:g} deg)"
            + (f"/coverage (>= {cfg.coverage_min_new:.0%} of the view seen in < {cfg.coverage_target_views} kept frames)"
               if use_cov else ", no coverage check (no mesh)"))
    why = [f"{skip_motion} too little motion"] if skip_motion else []
    why += [f"{skip_cov} no new surface"] if skip_cov else []
    why += [f"{len(kept) - len(out)} by the cap"] if len(out) < len(kept) else []
    reason = (f"kept {len(out)} of {n} frames: keyframes by {rule}, cap {cap}"
              + (f"; skipped {', '.join(why)}" if why else ""))
    return FrameSelection(out, n, reason, skip_motion, skip_cov, len(kept) - len(out))


def choose_frames(frames: Sequence[Frame], cfg: FrameSelectionConfig, rasterizer: Rasterizer | None = None) -> FrameSelection:
    """Select frames per ``cfg``; ``rasterizer`` (of the scan mesh) enables the coverage rule of keyframe mode."""
    frames = list(frames)
    if not frames:
        return FrameSelection([], 0, "no frames")
    if cfg.stride is None:
        return _keyframes(frames, cfg, rasterizer)
    out = frames[:: cfg.stride]
    filt = ""
    if cfg.keyframes:
        kept = [out[0]]
        for f in out[1:]:
            moved = np.linalg.norm(f.c2w[:3, 3] - kept[-1].c2w[:3, 3]) >= cfg.keyframe_translation_m
            if moved or _rotation_deg(kept[-1].c2w[:3, :3], f.c2w[:3, :3]) >= cfg.keyframe_rotation_deg:
                kept.append(f)
        out, filt = kept, f", then motion >= {cfg.keyframe_translation_m:g} m or >= {cfg.keyframe_rotation_deg:g} deg"
    capped = _even_cap(out, cfg.max_frames)
    reason = (f"kept {len(capped)} of {len(frames)} frames: stride {cfg.stride}{filt}"
              + (f", cap {cfg.max_frames}" if cfg.max_frames is not None else ""))
    return FrameSelection(capped, len(frames), reason, dropped_by_cap=len(out) - len(capped))


def selection_key(frames: Sequence[Frame], cfg: FrameSelectionConfig, mesh_path: str | Path) -> str:
    """What a selection depends on: the rules and settings, every frame's id, pose and intrinsics, and the
    mesh's bytes (coverage is measured on it)."""
    h = hashlib.sha256(f"{SELECTION_VERSION}|{cfg.model_dump_json()}".encode())
    for f in frames:
        h.update(f.frame_id.encode())
        h.update(np.ascontiguousarray(f.c2w, np.float64).tobytes())
        h.update(f.intrinsics.model_dump_json().encode())
    with open(mesh_path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def choose_frames_memo(frames: Sequence[Frame], cfg: FrameSelectionConfig, mesh_path: str | Path,
                       raster: Callable[[], Rasterizer], memo: SelectionMemo | None) -> FrameSelection:
    """:func:`choose_frames`, remembered in ``memo`` when the coverage rule runs (the costly one: it
    renders every candidate frame). ``raster()`` gives the scan's Rasterizer, called only when needed."""
    frames = list(frames)
    coverage = cfg.stride is None and cfg.coverage_width > 0
    if not coverage:
        return choose_frames(frames, cfg)
    if memo is None:
        return choose_frames(frames, cfg, raster())
    key = selection_key(frames, cfg, mesh_path)
    hit = memo.get(key)
    by_id = {f.frame_id: f for f in frames}
    if hit is not None and hit.get("frame_ids") and all(i in by_id for i in hit["frame_ids"]):
        return FrameSelection([by_id[i] for i in hit["frame_ids"]], len(frames), hit["reason"],
                              hit.get("skipped_motion", 0), hit.get("skipped_coverage", 0), hit.get("dropped_by_cap", 0))
    out = choose_frames(frames, cfg, raster())
    memo.put(key, {"frame_ids": [f.frame_id for f in out.frames], "reason": out.reason,
                   "skipped_motion": out.skipped_motion, "skipped_coverage": out.skipped_coverage,
                   "dropped_by_cap": out.dropped_by_cap})
    return out


def select_frames(frames: Sequence[Frame], cfg: FrameSelectionConfig, rasterizer: Rasterizer | None = None) -> list[Frame]:
    """The frames :func:`choose_frames` keeps."""
    return choose_frames(frames, cfg, rasterizer).frames
