"""The whole segmentation stage: lift every frame's masks, fuse, pick top-k views, re-segment, clip."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..config import FusionConfig, PipelineConfig
from ..data.frames import Frame, SceneInput
from ..data.masks import Mask2D
from ..data.mesh import TriMesh
from ..data.parts import PartCandidate
from ..geometry import overlap_counts
from ..perception.interfaces import PointPromptSegmenter
from ..raster import Rasterizer
from ..raster.rasterizer import RasterResult
from .clip import clip_part, is_lid_plane
from .connectivity import largest_component
from .lift import FrameLift, ViewStats, lift_with_stats
from .proposals import FusionMesh, Proposal, fuse_proposals, prepare_fusion_mesh
from .topk import top_views_from_stats

@dataclass
class ProposalOutcome:
    """What became of one fused proposal: ``status`` is ``candidate`` or why it made none
    (``no_views``, ``claimed`` by an earlier candidate, ``reseg_empty``, ``clip_empty``)."""

    status: str
    reseg_faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    kept_faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


@dataclass
class SegmentationTrace:
    """Intermediate results of one ``segment_parts`` run, kept only when asked for (miss-cause
    attribution, react3d_core.metrics.miss_causes): lifted masks, view statistics, Louvain proposals,
    each proposal's outcome and the candidates before the duplicate drop."""

    lifts: list[FrameLift] = field(default_factory=list)
    stats: list[ViewStats] = field(default_factory=list)
    proposals: list[Proposal] = field(default_factory=list)
    outcomes: list[ProposalOutcome] = field(default_factory=list)
    before_duplicates: list[PartCandidate] = field(default_factory=list)


def render_work(rasterizer: Rasterizer, frame: Frame, config: PipelineConfig) -> RasterResult:
    """Face-id buffer of ``frame`` at the fusion working width (config.fusion.work_width)."""
    intr = frame.intrinsics
    w = config.fusion.work_width
    if w is not None and w < intr.width:
        intr = intr.scaled(w, max(1, round(intr.height * w / intr.width)))
    return rasterizer.render_frame(frame, intr)


def lift_frames(
    scene: SceneInput, masks: Mapping[str, Sequence[Mask2D]], rasterizer: Rasterizer, config: PipelineConfig
) -> tuple[list[FrameLift], dict[str, RasterResult], list[ViewStats]]:
    """Render each frame with masks once (working width), lift its masks and collect its top-k
    statistics; keeps the buffers (face ids, depth) for re-segmentation."""
    lifts, buffers, stats = [], {}, []
    for f in scene.frames:
        ms = masks.get(f.frame_id)
        if not ms:
            continue
        r = render_work(rasterizer, f, config)
        buffers[f.frame_id] = r
        lift, st = lift_with_stats(r, list(ms), config)
        lifts.append(lift)
        stats.append(st)
    return lifts, buffers, stats


def _vertex_ids(mesh: TriMesh, faces: np.ndarray) -> np.ndarray:
    return np.unique(mesh.faces[faces].ravel()).astype(np.int64)


GENERIC_LABELS = ("", "openable")


def view_tag(views: Sequence) -> str:
    """Perception's name for a part: the most frequent specific label among its top views' masks
    (``"refrigerator door"``, a heuristic's ``"drawer"``), first seen on a tie; ``"openable"`` if none."""
    labels = [v.mask.label for v in views if getattr(v, "mask", None) is not None and v.mask.label not in GENERIC_LABELS]
    return max(dict.fromkeys(labels), key=labels.count) if labels else "openable"


def drop_duplicates(cands: list[PartCandidate], mesh: TriMesh, config: FusionConfig = FusionConfig()) -> list[PartCandidate]:
    """Proposals of several Louvain resolutions often re-segment to the same part, or to a piece of
    it (seen cut off in their best view): keep the best-scored candidate, drop later ones with
    vertex IoU > ``duplicate_iou`` or > ``duplicate_contained`` of their vertices inside a kept one
    (the dedup stage still runs later)."""
    order = sorted(cands, key=lambda c: (-c.score, -len(c.face_ids)))
    inter, size, _ = overlap_counts([c.vertex_ids for c in order])
    union = size[:, None] + size[None, :] - inter
    # [i, k]: candidate i duplicates k (IoU > duplicate_iou, written without the division) or lies in it
    dup = (inter > config.duplicate_iou * union) | (inter > config.duplicate_contained * size[:, None])
    keep: list[int] = []
    for i in range(len(order)):
        if not dup[i, keep].any():
            keep.append(i)
    kept = [order[i] for i in keep]
    for i, c in enumerate(kept):
        c.candidate_id = i
    return kept


def _instance(c: PartCandidate) -> int | None:
    """The perceived object most of ``c``'s top views' masks show (ties: the best view's), or None."""
    ids = [t.mask.instance for t in c.top_views if t.mask is not None and t.mask.instance is not None]
    if not ids:
        return None
    vals, counts = np.unique(ids, return_counts=True)
    best = vals[counts == counts.max()]
    return ids[0] if ids[0] in best else int(best[0])


def merge_instances(cands: list[PartCandidate], mesh: TriMesh) -> list[PartCandidate]:
    """Join the candidates whose top views show one perceived object (``_instance``) into the best-scored of
    them. Why: one object is one part; a front seen in pieces (a different piece past the clutter in each
    view) fuses into pieces, and each piece, re-segmented in the views that see it, became a part."""
    groups: dict[int, list[int]] = {}
    for i, c in enumerate(cands):
        k = _instance(c)
        if k is not None:
            groups.setdefault(k, []).append(i)
    gone: set[int] = set()
    for members in groups.values():
        if len(members) < 2:
            continue
        members = sorted(members, key=lambda i: (-cands[i].score, -len(cands[i].face_ids)))
        keep = cands[members[0]]
        faces = np.unique(np.concatenate([cands[i].face_ids for i in members]))
        keep.face_ids = faces
        keep.vertex_ids = _vertex_ids(mesh, faces)
        props = [cands[i].proposal_face_ids for i in members if cands[i].proposal_face_ids is not None]
        if props:
            keep.proposal_face_ids = np.unique(np.concatenate(props))
        gone.update(members[1:])
    out = [c for i, c in enumerate(cands) if i not in gone]
    for i, c in enumerate(out):
        c.candidate_id = i
    return out


def drop_lid_skirts(cands: list[PartCandidate], skirts: Sequence[tuple[int, np.ndarray]], share: float) -> list[PartCandidate]:
    """``cands`` less those with more than ``share`` of their faces among a lid's re-segmented or proposal
    faces (``skirts``: the lid's index in ``cands`` and those faces). Why: a lid is clipped to its top's plane, so
    its lip and side skirts are left over, and a proposal made of them, re-segmented before the lid claimed
    them, became a flap of its own beside the lid."""
    return [c for k, c in enumerate(cands)
            if not any(k != j and np.isin(c.face_ids, faces).mean() > share for j, faces in skirts)]


def candidates_from_proposals(
    scene: SceneInput,
    mesh: TriMesh,
    proposals: Sequence[Proposal],
    buffers: dict[str, RasterResult],
    stats: Sequence[ViewStats],
    masks: Mapping[str, Sequence[Mask2D]],
    point_segmenter: PointPromptSegmenter,
    rasterizer: Rasterizer,
    config: PipelineConfig,
    wfaces: np.ndarray,
    trace: SegmentationTrace | None = None,
) -> list[PartCandidate]:
    """Top-k views, re-segmentation in the best view and clipping for each proposal (``trace``: records
    each proposal's outcome)."""
    from .reseg import resegment

    tops = top_views_from_stats([p.face_ids for p in proposals], stats, masks, mesh.n_faces, config, mesh.face_areas)
    by_id = {f.frame_id: f for f in scene.frames}
    out = []
    centroids = mesh.face_centroids
    claimed = np.zeros(mesh.n_faces, bool)
    skirts: list[tuple[int, np.ndarray]] = []  # (candidate index, re-segmented and proposal faces) of each lid
    # best-seen proposals first; one mostly inside an earlier candidate would re-segment to it
    order = sorted(range(len(proposals)), key=lambda i: (-(tops[i][0].iou if tops[i] else 0.0), -len(proposals[i].face_ids)))
    outcomes = [ProposalOutcome("no_views") for _ in proposals]
    for i in order:
        prop, tv = proposals[i], tops[i]
        if not tv:
            continue
        if claimed[prop.face_ids].mean() > config.fusion.claimed_share:
            outcomes[i] = ProposalOutcome("claimed")
            continue
        frame = by_id[tv[0].frame_id]
        faces, _mask = resegment(frame, mesh, wfaces, centroids, prop.face_ids, tv, buffers, point_segmenter, rasterizer, config)
        if not len(faces):
            outcomes[i] = ProposalOutcome("reseg_empty")
            continue
        kept, n, d = clip_part(mesh, faces, frame.c2w[:3, 3], config.clip)
        if n is not None and len(kept):
            kept = largest_component(mesh, wfaces, kept, config.fusion.attach_m, config.fusion.keep_share)
        outcomes[i] = ProposalOutcome("candidate" if len(kept) else "clip_empty", np.asarray(faces, np.int64),
                                      np.asarray(kept, np.int64))
        if not len(kept):
            continue
        claimed[kept] = True
        if config.fusion.lid_claims_skirt and is_lid_plane(n, config.clip):
            # the best view's mask may miss an end skirt that the fused proposal holds
            skirt = np.union1d(np.asarray(faces, np.int64), prop.face_ids)
            skirts.append((len(out), skirt))
            claimed[skirt] = True
        out.append(
            PartCandidate(
                candidate_id=len(out),
                label=view_tag(tv),
                score=float(np.mean([t.iou for t in tv])),
                face_ids=kept,
                vertex_ids=_vertex_ids(mesh, kept),
                top_views=list(tv),
                seg_frame_id=frame.frame_id,
                plane_normal=None if n is None else tuple(float(x) for x in n),
                plane_offset=None if d is None else float(d),
                proposal_face_ids=prop.face_ids,
            )
        )
    out = drop_lid_skirts(out, skirts, config.fusion.claimed_share)
    if trace is not None:
        trace.outcomes = outcomes
        trace.before_duplicates = list(out)
    out = drop_duplicates(out, mesh, config.fusion)
    return merge_instances(out, mesh) if config.fusion.merge_instances else out


def pieces_config(masks: Mapping[str, Sequence[Mask2D]], config: PipelineConfig) -> PipelineConfig:
    """``config`` as the cuts to a connected component read it: ``fusion.keep_share`` holds only when the masks
    name the object they show (``Mask2D.instance``: a backend rendering each of its 3D fronts into every view,
    which sets it on every mask or none; the first mask tells). Such a mask is a whole front, so a piece holding
    a fifth of it is that front's; a detector's mask, or the oracle's noisy one, can reach into a neighbour, and a
    piece of that is not (oracle, held-apart glass: 112 -> 110 of 117 with the share)."""
    first = next((ms[0] for ms in masks.values() if len(ms)), None)
    if (first is not None and first.instance is not None) or config.fusion.keep_share >= 1.0:
        return config
    return config.model_copy(update={"fusion": config.fusion.model_copy(update={"keep_share": 1.0})})


def segment_parts(
    scene: SceneInput,
    mesh: TriMesh,
    masks: Mapping[str, Sequence[Mask2D]],
    point_segmenter: PointPromptSegmenter,
    config: PipelineConfig,
    rasterizer: Rasterizer | None = None,
    timings: dict[str, float] | None = None,
    fusion_mesh: FusionMesh | None = None,
    trace: SegmentationTrace | None = None,
) -> list[PartCandidate]:
    """Masks per frame -> movable-part candidates on the full-resolution scan, with their top-k views.

    ``timings`` (optional) receives seconds per sub-stage; ``fusion_mesh`` reuses a prepared
    (decimated, welded) mesh across calls; ``trace`` (optional) receives the intermediate results.
    """
    t = timings if timings is not None else {}
    config = pieces_config(masks, config)
    t0 = time.perf_counter()
    rasterizer = rasterizer or Rasterizer(mesh)
    fm = fusion_mesh or prepare_fusion_mesh(mesh, config)
    t1 = time.perf_counter()
    lifts, buffers, stats = lift_frames(scene, masks, rasterizer, config)
    t2 = time.perf_counter()
    proposals = fuse_proposals(lifts, mesh, config, fm)
    t3 = time.perf_counter()
    from .connectivity import welded_faces

    wfaces = fm.wfaces if fm.mesh is mesh else welded_faces(mesh, config.fusion.weld_m)
    t4 = time.perf_counter()
    if trace is not None:
        trace.lifts, trace.stats, trace.proposals = lifts, stats, list(proposals)
    cands = candidates_from_proposals(scene, mesh, proposals, buffers, stats, masks, point_segmenter, rasterizer, config,
                                      wfaces, trace)
    t5 = time.perf_counter()
    t.update(prepare=t1 - t0, weld_full=t4 - t3, lift=t2 - t1, fuse=t3 - t2, topk_reseg_clip=t5 - t4,
             n_proposals=float(len(proposals)), n_candidates=float(len(cands)))
    return cands
