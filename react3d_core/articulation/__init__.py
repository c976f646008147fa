"""Articulation stage: validate a candidate against the predictor, lift its joint, refine it on the OBB.

``articulate_candidate`` is the per-part entry point (a Prefect task per candidate); motion limits are
set later in assembly (``limits.set_limits``), once cavities and neighbours are known.
"""

from __future__ import annotations

import numpy as np

from ..config import PipelineConfig
from ..data.frames import SceneInput
from ..data.masks import ArticulationPrediction
from ..data.mesh import TriMesh
from ..data.parts import PartCandidate
from .obb import min_obb
from .refine import is_flat, refine_prismatic, refine_revolute, slab_mid_and_thickness
from .types import ArticulatedPart
from .validate import best_prediction, lift_prediction

STAGE_VERSION = "1"
__all__ = ["STAGE_VERSION", "ArticulatedPart", "articulate_candidate", "min_obb"]


def _frame_depth_rgb(scene: SceneInput, frame_id: str, rasterizer) -> np.ndarray | None:  # noqa: ANN001
    """Depth at the frame's RGB size: the sensor depth resized, else rendered from the mesh."""
    import cv2

    from ..scene_io.images import frame_depth

    f = next((f for f in scene.frames if f.frame_id == frame_id), None)
    if f is None:
        return None
    d = frame_depth(f)
    if d is not None:
        return cv2.resize(d, (f.intrinsics.width, f.intrinsics.height), interpolation=cv2.INTER_NEAREST)
    if rasterizer is not None:
        return rasterizer.render_frame(f).depth
    return None


def articulate_candidate(scene: SceneInput, mesh: TriMesh, candidate: PartCandidate,
                         predictions: dict[str, list[ArticulationPrediction]], config: PipelineConfig,
                         rasterizer=None) -> ArticulatedPart | None:  # noqa: ANN001
    """None when no prediction matches the candidate (IoU < valid_iou in every top view)."""
    pred, iou, view = best_prediction(candidate, predictions)
    if pred is None or iou < config.articulation.valid_iou:
        return None
    frame = next(f for f in scene.frames if f.frame_id == view)
    depth = _frame_depth_rgb(scene, view, rasterizer) if pred.origin_cam is None else None
    initial = lift_prediction(pred, frame, depth)
    pts = mesh.vertices[np.asarray(candidate.vertex_ids, np.int64)]
    obb = min_obb(pts)
    n = obb.R[:, 2].copy()
    seg_id = candidate.seg_frame_id or view
    cam = next((f.c2w[:3, 3] for f in scene.frames if f.frame_id == seg_id), frame.c2w[:3, 3])
    if candidate.plane_normal is not None:
        n *= 1.0 if np.dot(n, candidate.plane_normal) >= 0 else -1.0
    elif np.dot(n, np.asarray(obb.center) - cam) < 0:  # into the cavity = away from the camera
        n = -n
    mid, thickness = slab_mid_and_thickness(pts, np.asarray(obb.center), n)
    flat = is_flat(obb, config.articulation.flat_ratio)
    art = initial
    if config.articulation.refine and flat:
        art = refine_prismatic(initial, n) if initial.joint_type == "prismatic" else refine_revolute(initial, obb, mid)
    return ArticulatedPart(
        candidate_id=candidate.candidate_id, label=candidate.label, score=float(candidate.score * pred.score),
        face_ids=np.asarray(candidate.face_ids, np.int64), vertex_ids=np.asarray(candidate.vertex_ids, np.int64),
        initial=initial, articulation=art, obb=obb, front_normal=n, thickness=thickness, flat=flat,
        seg_frame_id=seg_id, top_views=[{"frame_id": v.frame_id, "iou": float(v.iou)} for v in candidate.top_views],
        validation_iou=iou)
