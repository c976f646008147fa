"""The heuristic backend's five calls, all answered from fronts found on the scan mesh (no weights).

Per frame, the scan mesh is rendered (at half resolution, upsampled) into a front-id image; masks,
point-prompt answers and articulation predictions are read off it. Renders are cached per frame so
the segmenter, the point segmenter and the predictor share them.
"""

from __future__ import annotations

import importlib
import logging
from collections import OrderedDict
from collections.abc import Callable, Sequence
import cv2
import numpy as np

from ...config.heuristic import HeuristicConfig, LineConfig
from ...data.frames import Frame, SceneInput
from ...data.masks import ArticulationPrediction, Mask2D
from ...data.mesh import TriMesh, load_mesh
from ...errors import ConfigError
from ...raster import Rasterizer
from ...scene_io.images import frame_rgb
from .behind_glass import seen_through_glass
from .classic_lines import lsd_detector
from .facets import planar_facets
from .constants import COLOUR_NDIM, RGB
from .fronts import Front, find_fronts
from .image_fronts import ImageFronts, find_image_fronts, floor_level
from .lids import chest_lids
from .reach import drawers_within_reach
from .room_walls import keep_room_doors
from .sliding import mark_sliding
from .splashback import on_worktop
from .view_agreement import agreement, interleaved_subsets, kept_by_agreement

log = logging.getLogger("react3d.perception")

OPENABLE_TAGS = ("cabinet", "drawer", "door", "wardrobe", "dresser", "refrigerator", "oven", "dishwasher")
# confidences the backend reports (fixed: the heuristic has no scores of its own)
MASK_SCORE = 0.9  # a front's mask in a frame
POINT_MASK_SCORE = 0.8  # the mask under point prompts (a front, else a facet)
JOINT_SCORE = 0.7  # a front's joint guess
_RENDER_CACHE = 16  # frames whose renders are kept: the segmenter, point segmenter and predictor share them
# the learned line-segment detector (perception.heuristic.lines) loads weights and a tflite runtime, so it
# lives outside the core: (module, loader taking the LineConfig), imported only when the section is enabled
LINE_DETECTOR = ("react3d_models.line_segments", "load_line_detector")


def load_line_detector(cfg: LineConfig) -> Callable[[np.ndarray], np.ndarray]:
    """The line-segment detector ``perception.heuristic.lines`` asks for (an RGB image -> segments (N, 4+)):
    OpenCV's LSD (``detector: lsd``, no weights) or the learned one from the weight-backed package
    (``mlsd``); a ConfigError (one line) when that cannot be loaded."""
    if cfg.detector == "lsd":
        return lsd_detector(cfg)
    module, attr = LINE_DETECTOR
    try:
        loader = getattr(importlib.import_module(module), attr)
    except ImportError as exc:
        raise ConfigError(f"perception.heuristic.lines needs the {module} module of this package: {exc}") from None
    return loader(cfg)


class HeuristicModel:
    """Facets, fronts and per-frame renders of one scene. Every threshold comes from ``config``
    (``perception.heuristic``; defaults when None). ``line_detector``: the learned line-segment detector
    to use when ``lines.enabled`` (default: the one the section names, loaded here)."""

    def __init__(self, scene: SceneInput, config: HeuristicConfig | None = None,
                 line_detector: Callable[[np.ndarray], np.ndarray] | None = None, *,
                 shared: HeuristicModel | None = None) -> None:
        h = config if config is not None else HeuristicConfig()
        rules = h.fronts
        self.config = h
        self.scene = scene
        # a model of the same scan mesh and facet rules (run again on a subset of the frames) lends its mesh,
        # rasteriser and facets: none of them depends on the frames
        same = shared is not None and shared.scene.mesh_path == scene.mesh_path and shared.config.facets == h.facets
        self.mesh: TriMesh = shared.mesh if same else load_mesh(scene.mesh_path)
        self.raster = shared.raster if same else Rasterizer(self.mesh)
        self.scale = h.render.scale
        self.facets = shared.facets if same else planar_facets(self.mesh, h.facets)
        self._cache: OrderedDict[str, tuple[np.ndarray, np.ndarray]] = OrderedDict()
        visible, glimpsed, view_dirs = self._visible_facets(h.probe.frames)
        cams = np.array([f.c2w[:3, 3] for f in scene.frames])
        self.fronts: list[Front] = find_fronts(self.mesh, self.facets, visible, cams.mean(0), rules, glimpsed, view_dirs)
        self.image: ImageFronts | None = None
        if h.image.enabled and self._has_colour():
            taken = np.zeros(self.mesh.n_faces, bool)
            for fr in self.fronts:
                taken[fr.faces] = True
            if h.lines.enabled and line_detector is None:
                line_detector = load_line_detector(h.lines)
            self.image = find_image_fronts(self.mesh, scene.frames, self.raster, frame_rgb, h, taken, self.fronts,
                                           line_detector)
            self.fronts = [f for k, f in enumerate(self.fronts) if k not in set(self.image.vetoed)] + self.image.fronts
            if h.image.glass_behind > 0 and self.image.panes:  # a glass cabinet's inside, seen through its doors
                inside = seen_through_glass(self.fronts, self.image.panes, h.image.glass_behind_min, h.image.glass_behind,
                                            h.image.glass_behind_share)
                self.fronts = [f for f, drop in zip(self.fronts, inside) if not drop]
        chest_lids(self.fronts, self.mesh, h.lids, rules.flap_max_deg)  # a chest's lip with a bar: its lid
        if h.splashback.enabled:  # fronts flush with the wall right above a worktop are splash-back
            self.fronts = [f for f, drop in zip(self.fronts, on_worktop(self.fronts, self.mesh, h.splashback)) if not drop]
        if h.room_wall.enabled:  # on the room's outer walls only room doors open
            self.fronts = keep_room_doors(self.fronts, self.mesh, h.room_wall, rules, h.floor, self.facets.labels)
        if h.reach.drawer_max_top > 0 and self.fronts:  # drawers are within reach
            self.fronts = drawers_within_reach(self.fronts, floor_level(self.mesh, h.floor), h.reach.drawer_max_top)
        self.agreement: list[int] | None = None  # per front: how many frame subsets found it again
        self.subset_fronts: list[list[Front]] | None = None  # the fronts each subset found
        if h.agreement.subsets >= 2 and self.fronts:
            self.subset_fronts = self._subset_runs(line_detector)
            if self.subset_fronts is not None:
                counts = agreement(self.fronts, self.subset_fronts, h.agreement.min_iou, h.agreement.plane_cos,
                                   h.agreement.plane_gap)
                self.fronts, self.agreement = kept_by_agreement(self.fronts, counts, h.agreement.min_runs)
        mark_sliding(self.fronts, h.sliding)  # two fronts a track apart: sliding doors
        self.face_front = np.full(self.mesh.n_faces + 1, -1, np.int32)  # last slot: background (-1 ids)
        for i, fr in enumerate(self.fronts):
            self.face_front[fr.faces] = i

    def _subset_runs(self, line_detector: Callable[[np.ndarray], np.ndarray] | None) -> list[list[Front]] | None:
        """The fronts found on each interleaved subset of the frames (``agreement.subsets``); None when a
        subset would hold fewer than ``agreement.min_frames`` frames."""
        ag = self.config.agreement
        frames = self.scene.frames
        if len(frames) < ag.subsets * ag.min_frames:
            log.info("heuristic: %d frames, too few for %d subsets of %d; no agreement test", len(frames),
                     ag.subsets, ag.min_frames)
            return None
        sub_cfg = self.config.model_copy(update={"agreement": ag.model_copy(update={"subsets": 0})})
        return [HeuristicModel(self.scene.model_copy(update={"frames": tuple(frames[i] for i in idx)}), sub_cfg,
                               line_detector, shared=self).fronts
                for idx in interleaved_subsets(len(frames), ag.subsets)]

    def _has_colour(self) -> bool:
        """True when the first frame's colour image reads as a 3-channel image; otherwise one warning
        line and the mesh-only path."""
        if not self.scene.frames:
            return False
        try:
            img = frame_rgb(self.scene.frames[0])
        except Exception as exc:  # noqa: BLE001 - any unreadable colour means: no image evidence
            log.warning("heuristic: colour frames unreadable (%s); finding fronts on the mesh only", exc)
            return False
        if img.ndim != COLOUR_NDIM or img.shape[2] < RGB or float(img.std()) == 0.0:
            log.warning("heuristic: frames carry no colour; finding fronts on the mesh only")
            return False
        return True

    def _visible_facets(self, n_probe: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per facet: clearly visible (>= ``probe.min_px`` px over >= ``probe.min_views`` probe views of
        >= ``probe.view_px`` px), glimpsed (any pixel), and the pixel-weighted sum of unit directions
        towards the cameras that saw it (orients its normal)."""
        h = self.config.probe
        idx = np.unique(np.linspace(0, len(self.scene.frames) - 1, min(n_probe, len(self.scene.frames))).round().astype(int))
        px = np.zeros(self.facets.n, np.int64)
        seen = np.zeros(self.facets.n, np.int64)
        centroids = self.mesh.face_centroids
        dirs = np.zeros((self.facets.n, centroids.shape[1]))
        for i in idx:
            f = self.scene.frames[i]
            intr = f.intrinsics.scaled(max(1, f.intrinsics.width // h.downscale), max(1, f.intrinsics.height // h.downscale))
            ids = self.raster.render(intr.K, f.c2w, intr.width, intr.height).face_ids
            hit = ids[ids >= 0]
            lab = self.facets.labels[hit]
            c = np.bincount(lab, minlength=self.facets.n)
            px += c
            seen += c >= h.view_px
            to_cam = f.c2w[:3, 3] - centroids[hit]
            to_cam /= np.maximum(np.linalg.norm(to_cam, axis=1, keepdims=True), 1e-9)
            for ax in range(dirs.shape[1]):
                dirs[:, ax] += np.bincount(lab, weights=to_cam[:, ax], minlength=self.facets.n)
        return (px >= h.min_px) & (seen >= h.min_views), px > 0, dirs

    def render(self, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
        """(front id, face id) images at the frame's RGB size; -1 = none."""
        hit = self._cache.get(frame.frame_id)
        if hit is not None:
            self._cache.move_to_end(frame.frame_id)
            return hit
        W, H = frame.intrinsics.width, frame.intrinsics.height
        intr = frame.intrinsics.scaled(max(1, round(W * self.scale)), max(1, round(H * self.scale)))
        ids = self.raster.render(intr.K, frame.c2w, intr.width, intr.height).face_ids
        ids = cv2.resize(ids, (W, H), interpolation=cv2.INTER_NEAREST)
        fronts = self.face_front[np.where(ids >= 0, ids, self.mesh.n_faces)]
        self._cache[frame.frame_id] = (fronts, ids)
        if len(self._cache) > _RENDER_CACHE:
            self._cache.popitem(last=False)
        return fronts, ids

    def masks(self, frame: Frame) -> list[tuple[int, np.ndarray]]:
        fronts, _ = self.render(frame)
        counts = np.bincount(fronts[fronts >= 0].ravel(), minlength=len(self.fronts))
        return [(int(k), fronts == k) for k in np.flatnonzero(counts >= self.config.render.min_mask_px)]


def _box(mask: np.ndarray) -> tuple[float, float, float, float]:
    ys, xs = np.nonzero(mask)
    return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())


class HeuristicTagger:
    def __init__(self, model: HeuristicModel) -> None:
        self.model = model

    def tag(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[str]]:
        return [["cabinet", "drawer", "door"] if self.model.masks(f) else [] for f in frames]


class KeepOpenable:
    """Tag filter: keeps the tags of a fixed openable vocabulary (always 'door')."""

    def filter(self, tags: Sequence[str]) -> list[str]:
        return sorted({t for t in tags if t in OPENABLE_TAGS} | {"door"})


class HeuristicSegmenter:
    def __init__(self, model: HeuristicModel) -> None:
        self.model = model

    def segment(self, frames: Sequence[Frame], images: Sequence[np.ndarray], phrases: Sequence[str]) -> list[list[Mask2D]]:
        out = []
        for f in frames:
            out.append([Mask2D(frame_id=f.frame_id, label=self.model.fronts[k].kind or "openable", score=MASK_SCORE, mask=m,
                               box=_box(m), instance=int(k))
                        for k, m in self.model.masks(f)])
        return out


class HeuristicPointSegmenter:
    """The front (else the planar facet) under most positive points."""

    def __init__(self, model: HeuristicModel) -> None:
        self.model = model

    def segment_points(self, frame: Frame, image: np.ndarray, points: np.ndarray, labels: np.ndarray) -> Mask2D:
        fronts, ids = self.model.render(frame)
        H, W = fronts.shape
        pos = np.asarray(points, float)[np.asarray(labels) > 0]
        if len(pos) == 0:
            return Mask2D(frame_id=frame.frame_id, mask=np.zeros((H, W), bool), score=0.0)
        x = np.clip(np.round(pos[:, 0]).astype(int), 0, W - 1)
        y = np.clip(np.round(pos[:, 1]).astype(int), 0, H - 1)
        under = fronts[y, x]
        if (under >= 0).any():
            k = np.bincount(under[under >= 0]).argmax()
            m = fronts == k
        else:
            fid = ids[y, x]
            fid = fid[fid >= 0]
            if len(fid) == 0:
                return Mask2D(frame_id=frame.frame_id, mask=np.zeros((H, W), bool), score=0.0)
            lab = self.model.facets.labels
            k = np.bincount(lab[fid]).argmax()
            m = (ids >= 0) & (lab[np.maximum(ids, 0)] == k)
        return Mask2D(frame_id=frame.frame_id, mask=m, score=POINT_MASK_SCORE, box=_box(m) if m.any() else None)


class HeuristicArticulation:
    def __init__(self, model: HeuristicModel) -> None:
        self.model = model

    def predict(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[ArticulationPrediction]]:
        out = []
        for f in frames:
            w2c = f.w2c
            preds = []
            for k, m in self.model.masks(f):
                a = self.model.fronts[k].articulation
                if a is None:
                    continue
                axis = w2c[:3, :3] @ np.asarray(a.axis)
                origin = w2c[:3, :3] @ np.asarray(a.origin) + w2c[:3, 3]
                preds.append(ArticulationPrediction(frame_id=f.frame_id, mask=m, joint_type=a.joint_type,
                                                    axis_cam=tuple(axis), origin_cam=tuple(origin), score=JOINT_SCORE,
                                                    sliding=self.model.fronts[k].kind == "sliding"))
            out.append(preds)
        return out
