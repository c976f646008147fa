"""Articulation stage: validate a candidate against the predictor (trimming a merge back to the predicted
part), lift its joint, refine it on the OBB.

``articulate_candidate`` is the per-part entry point (a Prefect task per candidate); motion limits are
set later in assembly (``limits.set_limits``), once cavities and neighbours are known.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import PipelineConfig
from ..data.frames import SceneInput
from ..data.masks import ArticulationPrediction
from ..data.mesh import TriMesh
from ..data.parts import OBB, Articulation, PartCandidate
from .obb import min_obb, trim_sparse_ends
from .refine import is_flat, refine_prismatic, refine_revolute, refine_sliding, slab_mid_and_thickness
from .sliding import sliding_agrees
from .trim import trim_to_prediction
from .types import ArticulatedPart
from .upright import upright_box
from .validate import best_prediction, consensus_joint, lift_prediction, matching_predictions, view_matches


@dataclass
class PartFit:
    """The part's box and front slab, everything refinement needs (shared by the stage and the ablation)."""

    obb: OBB
    front_normal: np.ndarray
    mid_center: np.ndarray
    thickness: float
    flat: bool


def fit_part(points: np.ndarray, camera: np.ndarray, plane_normal: np.ndarray | None, flat_ratio: float,
             upright_tolerance: float = 0.0, triangles: np.ndarray | None = None,
             sparse_end: tuple[float, float] | None = None) -> PartFit:
    """Min-area OBB (upright for a vertical front unless the minimal box is more than ``upright_tolerance``
    smaller, or whenever the clipping plane says the front is vertical, :func:`.upright.upright_box`);
    n_front = u1 x u2 oriented into the cavity: along the clipping plane's normal when the segmentation gave
    one, else away from the camera that segmented the part.
    With the part's ``triangles`` and ``sparse_end`` (density share, shortest end cut, m), the box's front
    sides end where its surface does (:func:`.obb.trim_sparse_ends`)."""
    obb = upright_box(points, min_obb(points), upright_tolerance, plane_normal=plane_normal)
    if triangles is not None and sparse_end is not None and sparse_end[0] > 0:
        obb = trim_sparse_ends(obb, triangles, min_density=sparse_end[0], min_trim_m=sparse_end[1])
    n = obb.R[:, 2].copy()
    if plane_normal is not None:
        n *= 1.0 if np.dot(n, plane_normal) >= 0 else -1.0
    elif np.dot(n, np.asarray(obb.center) - np.asarray(camera, float)) < 0:
        n = -n
    mid, thickness = slab_mid_and_thickness(points, np.asarray(obb.center), n)
    return PartFit(obb, n, mid, thickness, is_flat(obb, flat_ratio))


def refine_articulation(initial: Articulation, fit: PartFit, refine: bool = True, sliding: bool = False) -> Articulation:
    """The paper's refinement on flat parts; ``refine=False`` (ablation) or a non-flat part keeps the prediction.

    ``sliding``: the predictor says the prismatic part moves in its front plane (sliding door), so its
    axis is snapped onto an in-plane side of the OBB instead of the front normal."""
    if not (refine and fit.flat):
        return initial
    if initial.joint_type == "prismatic":
        return refine_sliding(initial, fit.obb) if sliding else refine_prismatic(initial, fit.front_normal)
    return refine_revolute(initial, fit.obb, fit.mid_center)


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
    matches = view_matches(candidate, predictions)  # one pass of mask IoUs for validation and consensus
    pred, iou, view = best_prediction(candidate, predictions, matches)
    if pred is None or iou < config.articulation.valid_iou:
        return None
    frames = {f.frame_id: f for f in scene.frames}
    if config.articulation.trim_to_prediction and rasterizer is not None:
        trimmed = trim_to_prediction(candidate, pred, view, predictions, frames, rasterizer, mesh)
        if trimmed is not candidate:  # a merge cut back to the predicted part: validate what is left
            candidate = trimmed
            matches = view_matches(candidate, predictions)
            pred, iou, view = best_prediction(candidate, predictions, matches)
            if pred is None or iou < config.articulation.valid_iou:
                return None
    frame = frames[view]

    def lifted(p: ArticulationPrediction, fid: str) -> Articulation:
        depth = _frame_depth_rgb(scene, fid, rasterizer) if p.origin_cam is None else None
        return lift_prediction(p, frames[fid], depth)

    initial = lifted(pred, view)
    if config.articulation.consensus_views:
        others = [lifted(p, fid) for p, fid in matching_predictions(candidate, predictions, config.articulation.valid_iou,
                                                                    matches) if p is not pred]
        initial = consensus_joint(initial, others)
    pts = mesh.vertices[np.asarray(candidate.vertex_ids, np.int64)]
    seg_id = candidate.seg_frame_id or view
    cam = next((f.c2w[:3, 3] for f in scene.frames if f.frame_id == seg_id), frame.c2w[:3, 3])
    tris = mesh.vertices[mesh.faces[np.asarray(candidate.face_ids, np.int64)]]
    ac = config.articulation
    fit = fit_part(pts, cam, candidate.plane_normal, ac.flat_ratio, ac.upright_tolerance, tris,
                   (ac.sparse_end_density, ac.sparse_end_min_m))
    obb, n, thickness, flat = fit.obb, fit.front_normal, fit.thickness, fit.flat
    sliding = bool(pred.sliding and pred.joint_type == "prismatic") and sliding_agrees(
        initial.axis, obb, n, candidate.label, config.articulation.sliding_min_height_m)
    art = refine_articulation(initial, fit, config.articulation.refine, sliding)
    return ArticulatedPart(
        candidate_id=candidate.candidate_id, label=candidate.label, score=float(candidate.score * pred.score),
        face_ids=np.asarray(candidate.face_ids, np.int64), vertex_ids=np.asarray(candidate.vertex_ids, np.int64),
        initial=initial, articulation=art, obb=obb, front_normal=n, thickness=thickness, flat=flat,
        seg_frame_id=seg_id, top_views=[{"frame_id": v.frame_id, "iou": float(v.iou)} for v in candidate.top_views],
        validation_iou=iou, sliding=sliding)
