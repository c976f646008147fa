"""Front-level detection score of a perception step: predicted fronts (face sets on the scan mesh)
against ground-truth movable parts (their faces with the parts below them, e.g. handles).

Why: deciding a heuristic threshold with the whole pipeline takes an hour per set; the fronts the
perception step hands on take minutes, and a front that does not match a part here cannot become a
matched part later. Matching: area IoU of face sets >= ``threshold``, greedy one-to-one from the
highest IoU (the paper's protocol uses vertex IoU on the final parts; this is a development score).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..geometry import iou_matrix


@dataclass(frozen=True)
class FrontScore:
    """Matched pairs (gt index, prediction index, IoU) and the counts behind precision / recall / F1."""

    pairs: tuple[tuple[int, int, float], ...]
    n_pred: int
    n_gt: int

    @property
    def tp(self) -> int:
        return len(self.pairs)

    @property
    def precision(self) -> float:
        return self.tp / self.n_pred if self.n_pred else 0.0

    @property
    def recall(self) -> float:
        return self.tp / self.n_gt if self.n_gt else 0.0

    @property
    def f1(self) -> float:
        return 2 * self.tp / (self.n_pred + self.n_gt) if self.n_pred + self.n_gt else 0.0


def match_fronts(gt: Sequence[np.ndarray], pred: Sequence[np.ndarray], face_area: np.ndarray,
                 threshold: float = 0.5) -> FrontScore:
    """Greedy one-to-one matching by area IoU (highest first) at ``threshold``."""
    iou = iou_matrix(gt, pred, face_area)
    cand = sorted(((float(iou[i, j]), i, j) for i, j in zip(*np.nonzero(iou >= threshold))), reverse=True)
    used_g: set[int] = set()
    used_p: set[int] = set()
    pairs = []
    for v, i, j in cand:
        if i in used_g or j in used_p:
            continue
        used_g.add(i)
        used_p.add(j)
        pairs.append((int(i), int(j), v))
    return FrontScore(tuple(sorted(pairs)), len(pred), len(gt))
