"""Frame selection: stride, then keyframes by pose change, then an even cap (FrameSelectionConfig)."""

from __future__ import annotations

import numpy as np

from ..config.frames import FrameSelectionConfig
from ..data.frames import Frame


def _rotation_deg(Ra: np.ndarray, Rb: np.ndarray) -> float:
    c = (np.trace(Ra.T @ Rb) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def select_frames(frames: list[Frame] | tuple[Frame, ...], cfg: FrameSelectionConfig) -> list[Frame]:
    """Apply stride, keyframe filter (translation OR rotation above threshold), then max_frames evenly."""
    out = list(frames)[:: cfg.stride]
    if cfg.keyframes and out:
        kept = [out[0]]
        for f in out[1:]:
            last = kept[-1].c2w
            cur = f.c2w
            moved = np.linalg.norm(cur[:3, 3] - last[:3, 3]) >= cfg.keyframe_translation_m
            turned = _rotation_deg(last[:3, :3], cur[:3, :3]) >= cfg.keyframe_rotation_deg
            if moved or turned:
                kept.append(f)
        out = kept
    if cfg.max_frames is not None and len(out) > cfg.max_frames:
        idx = np.unique(np.round(np.linspace(0, len(out) - 1, cfg.max_frames)).astype(int))
        out = [out[i] for i in idx]
    return out
