"""Segmentation quality against ground truth: vertex-IoU matching of candidates to movable GT parts.

Used by the fusion tests and benchmark on synthetic scenes (the full evaluation is react3d_core.metrics).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..data.parts import PartCandidate
from ..geometry import iou_matrix
from ..ground_truth import GroundTruth


@dataclass
class SegmentationQuality:
    """``iou[i, j]``: vertex IoU of candidate i with movable GT part j (handles included)."""

    part_ids: list[int]
    iou: np.ndarray
    eligible: list[int] = field(default_factory=list)  # GT parts seen in enough frames

    def recall(self, thr: float = 0.5) -> float:
        """Share of eligible GT parts with a candidate of IoU >= ``thr``."""
        cols = [self.part_ids.index(p) for p in self.eligible]
        if not cols:
            return 1.0
        best = self.iou[:, cols].max(0) if len(self.iou) else np.zeros(len(cols))
        return float(np.mean(best >= thr))

    def precision(self, thr: float = 0.5) -> float:
        """Share of candidates matching some movable GT part with IoU >= ``thr``."""
        if not len(self.iou):
            return 1.0
        return float(np.mean(self.iou.max(1) >= thr))

    def best_iou(self, part_id: int) -> float:
        j = self.part_ids.index(part_id)
        return float(self.iou[:, j].max()) if len(self.iou) else 0.0


def segmentation_quality(cands: Sequence[PartCandidate], gt: GroundTruth, frames_seen: Mapping[int, int], min_frames: int = 3) -> SegmentationQuality:
    """Match candidates to movable GT parts (with their handles); eligible = seen in >= ``min_frames``."""
    parts = gt.movable_vertex_sets(include_children=True)
    ids = list(parts)
    iou = iou_matrix([c.vertex_ids for c in cands], list(parts.values()))
    return SegmentationQuality(ids, iou, [p for p in ids if frames_seen.get(p, 0) >= min_frames])
