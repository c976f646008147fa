"""Oracle perception: answers the five model calls from ground truth, made imperfect on purpose.

Why: it isolates the geometric stages (fusion, articulation, assembly) from model quality, and
``OracleNoiseConfig`` dials in the failure modes the paper's models show (bleeding boundaries,
missed handles, dropped or merged detections, whole-object masks, false positives, noisy axes).
Part pixels come from the GT part-id images (``Frame.part_ids``, value = partId + 1); scenes
without them are rendered from the GT ``triIndices`` with the Rasterizer. All noise is seeded per
(seed, frame id), so a frame's answer does not depend on which batch it came in.
"""

from __future__ import annotations

import zlib
from collections import OrderedDict
from collections.abc import Sequence

import cv2
import numpy as np

from ..camera import scaled_px
from ..config import OracleNoiseConfig, PerceptionConfig
from ..data.frames import Frame, SceneInput
from ..data.masks import ArticulationPrediction, Mask2D
from ..errors import InputError
from ..ground_truth import GroundTruth, read_articulate3d
from .interfaces import Perception
from .versions import ORACLE_VERSION

STAGE_VERSION = ORACLE_VERSION  # history in react3d_core/perception/versions.py


def _disk(r: int) -> np.ndarray:
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))


def _box(mask: np.ndarray) -> tuple[float, float, float, float] | None:
    ys, xs = np.nonzero(mask)
    if not len(xs):
        return None
    return float(xs.min()), float(ys.min()), float(xs.max() + 1), float(ys.max() + 1)


def _rotate_small(v: np.ndarray, deg: float, rng: np.random.Generator) -> np.ndarray:
    """Rotate unit ``v`` by a N(0, deg) angle about a random axis perpendicular to it."""
    if deg <= 0:
        return v
    r = rng.normal(size=3)
    r -= r.dot(v) * v
    if np.linalg.norm(r) < 1e-9:
        return v
    r /= np.linalg.norm(r)
    a = np.deg2rad(rng.normal(0.0, deg))
    return np.cos(a) * v + np.sin(a) * np.cross(r, v)


class OracleModel:
    """Ground truth of one scene: part hierarchy, per-frame part-id images (cached) and noise."""

    def __init__(self, scene: SceneInput, noise: OracleNoiseConfig, gt: GroundTruth | None = None, cache: int = 8) -> None:
        if gt is None:
            if scene.gt_dir is None:
                raise InputError(scene.root, "the oracle backend needs ground truth (no gt_dir)")
            gt = read_articulate3d(scene.gt_dir)
        self.scene, self.noise, self.gt = scene, noise, gt
        self.parts = {p.part_id: p for p in gt.parts}
        self.movable = [p.part_id for p in gt.movable]
        mov = set(self.movable)
        # owner: part id -> the movable part it moves with (itself, or its parent for a handle)
        self.owner: dict[int, int] = {pid: pid for pid in mov}
        self.handles: dict[int, list[int]] = {pid: [] for pid in mov}
        for p in gt.parts:
            if p.part_id in mov:
                continue
            for m in gt.movable:
                if p.label.startswith(m.label + "."):
                    self.owner[p.part_id] = m.part_id
                    if p.label.endswith(".handle"):
                        self.handles[m.part_id].append(p.part_id)
                    break
        self._cache: OrderedDict[str, np.ndarray] = OrderedDict()
        self._cache_size = cache
        self._raster = None
        self._sliding: dict[int, bool] | None = None

    # -- pixels -------------------------------------------------------------------------------
    def part_image(self, frame: Frame) -> np.ndarray:
        """int32 HxW GT part id per pixel (-1 = none), at the frame's RGB size."""
        hit = self._cache.get(frame.frame_id)
        if hit is not None:
            self._cache.move_to_end(frame.frame_id)
            return hit
        if frame.part_ids is not None and frame.part_ids.path.is_file():
            from ..scene_io.images import read_label_image

            img = read_label_image(frame.part_ids) - 1
            w, h = frame.intrinsics.width, frame.intrinsics.height
            if img.shape != (h, w):
                img = cv2.resize(img.astype(np.float32), (w, h), interpolation=cv2.INTER_NEAREST).astype(np.int32)
        else:
            img = self._render(frame)
        self._cache[frame.frame_id] = img
        if len(self._cache) > self._cache_size:
            self._cache.popitem(last=False)
        return img

    def _render(self, frame: Frame) -> np.ndarray:
        """Fallback without part-id images: rasterise the scan and look up each face's GT part."""
        if self._raster is None:
            from ..data.mesh import load_mesh
            from ..raster import Rasterizer

            mesh = load_mesh(self.scene.mesh_path)
            lut = np.full(mesh.n_faces + 1, -1, np.int32)  # last slot: background (-1)
            for p in self.gt.parts:  # children after parents so handles win over their door
                t = p.tri_indices[(p.tri_indices >= 0) & (p.tri_indices < mesh.n_faces)]
                lut[t] = p.part_id
            self._raster, self._lut = Rasterizer(mesh), lut
        ids = self._raster.render_frame(frame).face_ids
        return self._lut[ids]

    def sliding(self, pid: int) -> bool:
        """GT prismatic joint in the part's own plane (a sliding door): the part is flat (its thinnest spread
        under half the next) and the axis makes > 45 deg with its thinnest direction (the front normal:
        the least-variance direction of its vertices). A drawer with its box in the GT is not flat."""
        if self._sliding is None:
            from ..data.mesh import load_mesh

            verts = load_mesh(self.scene.mesh_path).vertices
            self._sliding = {}
            for p in self.gt.movable:
                art, ids = p.articulation, p.vert_indices[(p.vert_indices >= 0) & (p.vert_indices < len(verts))]
                if art is None or art.joint_type != "prismatic" or len(ids) < 4:
                    self._sliding[p.part_id] = False
                    continue
                pts = verts[ids] - verts[ids].mean(0)
                ev, vecs = np.linalg.eigh(pts.T @ pts)
                flat = np.sqrt(max(ev[0], 0.0)) < 0.5 * np.sqrt(max(ev[1], 0.0))
                in_plane = abs(float(np.dot(vecs[:, 0], art.axis))) < np.cos(np.radians(45.0))
                self._sliding[p.part_id] = bool(flat and in_plane)
        return self._sliding.get(pid, False)

    def part_region(self, img: np.ndarray, pid: int, with_handles: bool) -> np.ndarray:
        ids = [pid] + (self.handles.get(pid, []) if with_handles else [])
        return np.isin(img, ids)

    def rng(self, frame: Frame, stream: int) -> np.random.Generator:
        return np.random.default_rng([self.noise.seed, zlib.crc32(frame.frame_id.encode()), stream])

    def boundary(self, mask: np.ndarray) -> np.ndarray:
        """Dilate (>0) or erode (<0) by ``boundary_px`` scaled to the image width."""
        r = scaled_px(abs(self.noise.boundary_px), mask.shape[1])
        if r == 0 or not mask.any():
            return mask
        op = cv2.dilate if self.noise.boundary_px > 0 else cv2.erode
        return op(mask.astype(np.uint8), _disk(r)).astype(bool)

    def visible_movable(self, img: np.ndarray) -> list[tuple[int, np.ndarray]]:
        """Movable parts with >= min_visible_px pixels (part + handles), with their full regions."""
        present = np.unique(img[img >= 0])
        out = []
        for pid in self.movable:
            if pid not in present and not any(h in present for h in self.handles[pid]):
                continue
            reg = self.part_region(img, pid, True)
            if reg.sum() >= max(1, self.noise.min_visible_px):
                out.append((pid, reg))
        return out

    # -- the calls ----------------------------------------------------------------------------
    def masks(self, frame: Frame) -> list[Mask2D]:
        """Openable-part masks of one frame with drops, merges, whole-object masks and false positives."""
        nz, img = self.noise, self.part_image(frame)
        rng = self.rng(frame, 0)
        vis = self.visible_movable(img)
        used: set[int] = set()
        out: list[Mask2D] = []
        for i, (pid, reg) in enumerate(vis):
            drop, merge, whole = rng.random(3)
            if pid in used:
                continue
            used.add(pid)
            if drop < nz.drop_rate:
                continue
            m = self.part_region(img, pid, not nz.handle_holes)
            if merge < nz.merge_rate:
                grown = cv2.dilate(reg.astype(np.uint8), _disk(3)).astype(bool)
                for pj, rj in vis[i + 1 :]:
                    if pj not in used and (grown & rj).any():
                        m = m | self.part_region(img, pj, not nz.handle_holes)
                        used.add(pj)
                        break
            if whole < nz.whole_object_rate and self.parts[pid].base:
                m = m | np.isin(img, self.parts[pid].base)
            m = self.boundary(m)
            if m.any():
                out.append(Mask2D(frame_id=frame.frame_id, label="openable", score=1.0, mask=m, box=_box(m)))
        h, w = img.shape
        for _ in range(int(rng.poisson(nz.false_positive_rate)) if nz.false_positive_rate > 0 else 0):
            bw, bh = (rng.uniform(0.05, 0.2, 2) * [w, h]).astype(int) + 1
            x0, y0 = int(rng.integers(0, max(1, w - bw))), int(rng.integers(0, max(1, h - bh)))
            m = np.zeros((h, w), bool)
            m[y0 : y0 + bh, x0 : x0 + bw] = True
            out.append(Mask2D(frame_id=frame.frame_id, label="openable", score=0.5, mask=m, box=_box(m)))
        return out

    def point_mask(self, frame: Frame, points: np.ndarray, labels: np.ndarray) -> Mask2D:
        """The GT part under most positive points (a handle answers with its door), with the same
        boundary, handle-hole and whole-object noise as the masks (seeded by frame and points)."""
        img = self.part_image(frame)
        h, w = img.shape
        pts = np.asarray(points, float).reshape(-1, 2)
        pos = pts[np.asarray(labels).reshape(-1) == 1] if len(pts) else pts
        uv = np.round(pos).astype(int)
        ok = (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
        under = img[uv[ok, 1], uv[ok, 0]]
        under = np.array([self.owner.get(int(p), int(p)) for p in under if p >= 0], dtype=np.int64)
        if not len(under):
            return Mask2D(frame_id=frame.frame_id, score=0.0, mask=np.zeros((h, w), bool))
        vals, counts = np.unique(under, return_counts=True)
        pid = int(vals[np.argmax(counts)])
        m = self.part_region(img, pid, not self.noise.handle_holes) if pid in self.handles else img == pid
        rng = np.random.default_rng([self.noise.seed, zlib.crc32(frame.frame_id.encode()), 2,
                                     zlib.crc32(np.round(pos).astype(np.int64).tobytes())])
        if pid in self.handles and self.parts[pid].base and rng.random() < self.noise.whole_object_rate:
            m = m | np.isin(img, self.parts[pid].base)  # SAM often answers a door click with the cabinet
        m = self.boundary(m)
        label = "openable" if pid in self.handles else self.parts[pid].label
        return Mask2D(frame_id=frame.frame_id, label=label, score=1.0, mask=m, box=_box(m))

    def predictions(self, frame: Frame) -> list[ArticulationPrediction]:
        """Per visible movable part: GT joint in this camera's frame, with type flips and axis/origin noise."""
        nz, img = self.noise, self.part_image(frame)
        rng = self.rng(frame, 1)
        w2c = frame.w2c
        out = []
        for pid, _reg in self.visible_movable(img):
            drop, flip = rng.random(2)
            axis_rng = np.random.default_rng(rng.integers(1 << 62))
            if drop < nz.drop_rate:
                continue
            art = self.parts[pid].articulation
            assert art is not None
            jt = art.joint_type
            if flip < nz.type_flip_rate:
                jt = "prismatic" if jt == "revolute" else "revolute"
            a = _rotate_small(np.asarray(art.axis, float), nz.axis_noise_deg, axis_rng)
            o = np.asarray(art.origin, float) + axis_rng.normal(0.0, nz.origin_noise_m / np.sqrt(3.0), 3)
            a_cam = w2c[:3, :3] @ a
            o_cam = w2c[:3, :3] @ o + w2c[:3, 3]
            m = self.boundary(self.part_region(img, pid, not nz.handle_holes))
            out.append(
                ArticulationPrediction(
                    frame_id=frame.frame_id, mask=m, joint_type=jt,
                    axis_cam=tuple(float(x) for x in a_cam / np.linalg.norm(a_cam)),
                    origin_cam=tuple(float(x) for x in o_cam), score=1.0,
                    sliding=jt == "prismatic" and art.joint_type == "prismatic" and self.sliding(pid),
                )
            )
        return out

    def tags(self, frame: Frame) -> list[str]:
        """Words of the GT labels seen in the frame ('kitchen_cabinet.door_1' -> 'kitchen cabinet', 'door')."""
        img = self.part_image(frame)
        words: set[str] = set()
        for pid in np.unique(img[img >= 0]):
            p = self.parts.get(int(pid))
            if p is None:
                continue
            for tok in p.label.split("."):
                words.add(" ".join(t for t in tok.split("_") if not t.isdigit()))
        return sorted(w for w in words if w)


class OracleTagger:
    def __init__(self, model: OracleModel) -> None:
        self.model = model

    def tag(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[str]]:
        return [self.model.tags(f) for f in frames]


class KeepAll:
    """The oracle's tag filter keeps every tag: openability comes from the GT articulations."""

    def filter(self, tags: Sequence[str]) -> list[str]:
        return list(tags)


class OracleSegmenter:
    def __init__(self, model: OracleModel) -> None:
        self.model = model

    def segment(self, frames: Sequence[Frame], images: Sequence[np.ndarray], phrases: Sequence[str]) -> list[list[Mask2D]]:
        return [self.model.masks(f) for f in frames]


class OraclePointSegmenter:
    def __init__(self, model: OracleModel) -> None:
        self.model = model

    def segment_points(self, frame: Frame, image: np.ndarray, points: np.ndarray, labels: np.ndarray) -> Mask2D:
        return self.model.point_mask(frame, points, labels)


class OracleArticulation:
    def __init__(self, model: OracleModel) -> None:
        self.model = model

    def predict(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[ArticulationPrediction]]:
        return [self.model.predictions(f) for f in frames]


def make_oracle(scene: SceneInput, config: PerceptionConfig) -> Perception:
    """The oracle backend for ``scene`` (needs its GT); noise from ``config.oracle``."""
    model = OracleModel(scene, config.oracle)
    return Perception(
        name="oracle",
        tagger=OracleTagger(model),
        tag_filter=KeepAll(),
        segmenter=OracleSegmenter(model),
        point_segmenter=OraclePointSegmenter(model),
        articulation=OracleArticulation(model),
        version=STAGE_VERSION,
    )
