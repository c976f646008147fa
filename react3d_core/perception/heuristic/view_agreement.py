"""Fronts the views agree on: a front found again on subsets of the frames.

Why: the image path fuses many views per plane, and some of its fronts come from one mixture of views
rather than from the scan: colour only a few views paint on a wall, a cut along the edge of what one
occluder hides. Found again on a third of the frames, a true front comes back, cut a little differently;
such an artefact does not come back at all.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np

from .fronts import Front

log = logging.getLogger("react3d.perception")


def interleaved_subsets(n_frames: int, k: int) -> list[np.ndarray]:
    """Indices of ``n_frames`` dealt into ``k`` subsets, every ``k``-th frame from offsets 0..k-1: each subset
    spans the whole capture (all its viewpoints, sparser), unlike consecutive chunks."""
    if k < 1:
        raise ValueError(f"need at least one subset, got {k}")
    return [np.arange(j, n_frames, k) for j in range(k)]


def same_plane(f: Front, g: Front, plane_cos: float, plane_gap: float) -> bool:
    """Whether fronts ``f`` and ``g`` lie on one plane: normals alike (dot >= ``plane_cos``) and centres at
    most ``plane_gap`` apart along ``f``'s normal."""
    n_f, n_g = np.asarray(f.n_out, float), np.asarray(g.n_out, float)
    if float(n_f @ n_g) < plane_cos:
        return False
    return abs(float((np.asarray(g.center, float) - np.asarray(f.center, float)) @ n_f)) <= plane_gap


def rect_iou(f: Front, g: Front) -> float:
    """IoU of the rectangles of two fronts on one plane, read on ``f``'s axes (``u`` and the in-plane axis
    square to it): each rectangle is its centre there, +- half its own width and height. Centres, not the
    ``extent`` pairs, since those are measured along each front's own axis, which may point either way."""
    n = np.asarray(f.n_out, float)
    u = np.asarray(f.u, float)
    u = u / max(float(np.linalg.norm(u)), 1e-12)
    v = np.cross(n, u)
    v = v / max(float(np.linalg.norm(v)), 1e-12)
    cf, cg = np.asarray(f.center, float), np.asarray(g.center, float)
    du = abs(float((cg - cf) @ u))
    dv = abs(float((cg - cf) @ v))
    ou = min(0.5 * (f.w + g.w) - du, f.w, g.w)
    ov = min(0.5 * (f.h + g.h) - dv, f.h, g.h)
    if ou <= 0 or ov <= 0:
        return 0.0
    inter = ou * ov
    union = f.w * f.h + g.w * g.h - inter
    return float(inter / union) if union > 0 else 0.0


def holds(f: Front, run: Sequence[Front], min_iou: float, plane_cos: float, plane_gap: float) -> bool:
    """Whether ``run`` (the fronts found on one subset) holds ``f``: one of them on ``f``'s plane overlaps
    it at rectangle IoU >= ``min_iou``."""
    return any(same_plane(f, g, plane_cos, plane_gap) and rect_iou(f, g) >= min_iou for g in run)


def agreement(fronts: Sequence[Front], runs: Sequence[Sequence[Front]], min_iou: float, plane_cos: float,
              plane_gap: float) -> list[int]:
    """For each of ``fronts``: how many of ``runs`` hold it (``holds``)."""
    return [sum(holds(f, run, min_iou, plane_cos, plane_gap) for run in runs) for f in fronts]


def kept_by_agreement(fronts: Sequence[Front], counts: Sequence[int], min_runs: int) -> tuple[list[Front], list[int]]:
    """The fronts that at least ``min_runs`` subsets hold (``counts`` from ``agreement``), and their counts;
    one log line names how many went."""
    keep = [k for k, c in enumerate(counts) if c >= min_runs]
    if len(keep) < len(fronts):
        log.info("heuristic: %d of %d fronts found again on fewer than %d frame subsets; dropped",
                 len(fronts) - len(keep), len(fronts), min_runs)
    return [fronts[k] for k in keep], [int(counts[k]) for k in keep]
