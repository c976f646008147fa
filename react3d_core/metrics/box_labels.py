"""Evaluate a converted scene against hand-drawn 2D boxes of its fronts (scans without 3D ground truth).

Real scans (e.g. 7-Scenes RedKitchen) have no Articulate3D annotation, but a person can draw one box per
visible front in a handful of colour frames. Each predicted part is projected into those frames through the
frame poses, **occlusion-aware**: the scan mesh is rendered to a depth buffer and only part vertices not
behind the scan surface by more than ``depth_tol`` (3 cm) count, so a part hidden behind a chair or a
counter does not claim the pixels of what is in front of it. The box of its visible projection is compared
with the labelled box by IoU.

Matching is one-to-one (Hungarian, ``scipy.optimize.linear_sum_assignment``) on the score
``S[part, front]`` = mean box IoU over the frames where the front is labelled (0 in a frame where the part
is not visible). A front is **found** when its matched part has ``S >= iou_threshold`` (default 0.5). A
**false part** is a predicted part visible in at least one labelled frame that is not matched to a found
front and does not fall into an ``ignore`` box (at least ``ignore_cover`` of its visible box inside one):
ignore boxes mark things that are seen too poorly to be labelled (e.g. upper cabinets seen only from
below), so a part there is neither a hit nor a miss.

Label file (JSON)::

    {"image_size": [640, 480],
     "frames": {"frame-000064": {"fronts": {"L1": [x0, y0, x1, y1], ...}, "ignore": [[x0, y0, x1, y1]],
                                 "render_to_photo": [[a, b, tx], [c, d, ty]]}}}

Boxes are drawn on the colour photo. Where the photo is not registered to the pose projection (7-Scenes:
the poses are the depth camera's; the colour differs by a per-frame scale and shift), an optional 2x3
affine ``render_to_photo`` (photo pixel = A [u, v, 1] of the pose-projection pixel) maps them into the
pose projection on loading, so a part that exactly covers a front is not penalised for the sensor's
misregistration.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..data.frames import Frame, SceneInput
from ..data.mesh import TriMesh, load_mesh

Box = tuple[float, float, float, float]


@dataclass(frozen=True)
class FrameLabels:
    """Labelled fronts (id -> box) and ignore boxes of one frame, in pixels of ``image_size``."""

    fronts: dict[str, Box]
    ignore: tuple[Box, ...] = ()
    render_to_photo: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None


@dataclass(frozen=True)
class BoxLabels:
    """All labelled frames of one scene; ``image_size`` is (width, height) the boxes were drawn at."""

    frames: dict[str, FrameLabels]
    image_size: tuple[int, int]

    @property
    def front_ids(self) -> list[str]:
        """Every front id, sorted, labelled in at least one frame."""
        return sorted({k for fl in self.frames.values() for k in fl.fronts})


@dataclass(frozen=True)
class PredictedPart:
    """One movable part of a converted scene: its closed-state vertices (world) and its joint."""

    object_id: str
    vertices: np.ndarray
    joint_type: str
    axis: tuple[float, float, float] | None = None

    @property
    def joint_class(self) -> str:
        """'prismatic', 'revolute_vertical' or 'revolute_horizontal' (< 45 deg to the ground is horizontal)."""
        return joint_class_of(self.joint_type, self.axis)


@dataclass
class FrontResult:
    """Outcome for one labelled front: the part the one-to-one matching gave it (if any overlaps), its mean box
    IoU, its best IoU with any other front (a merged part scores on two), and ``found`` = IoU >= threshold."""

    front_id: str
    found: bool
    part: str | None = None
    iou: float = 0.0
    other_iou: float = 0.0
    joint_type: str | None = None
    joint_class: str | None = None
    per_frame_iou: dict[str, float] = field(default_factory=dict)


@dataclass
class BoxLabelReport:
    """Per-front outcome plus the totals a benchmark or a test asserts on."""

    fronts: list[FrontResult]
    false_parts: list[str]
    ignored_parts: list[str]
    unseen_parts: list[str]
    n_parts: int
    iou_threshold: float
    part_boxes: dict[str, dict[str, list[float]]] = field(default_factory=dict)

    @property
    def n_found(self) -> int:
        return sum(f.found for f in self.fronts)

    @property
    def n_fronts(self) -> int:
        return len(self.fronts)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (totals first)."""
        return {"n_fronts": self.n_fronts, "n_found": self.n_found, "n_false_parts": len(self.false_parts),
                "n_parts": self.n_parts, "iou_threshold": self.iou_threshold,
                "fronts": [asdict(f) for f in self.fronts], "false_parts": self.false_parts,
                "ignored_parts": self.ignored_parts, "unseen_parts": self.unseen_parts, "part_boxes": self.part_boxes}


def joint_class_of(joint_type: str, axis: Any) -> str:
    """3-way joint taxonomy of the paper: revolute is horizontal when its axis makes < 45 deg with the ground."""
    if joint_type != "revolute":
        return joint_type
    a = np.asarray(axis if axis is not None else (0.0, 0.0, 1.0), float)
    n = float(np.linalg.norm(a))
    return "revolute_vertical" if n > 0 and abs(a[2]) / n >= np.sin(np.radians(45.0)) else "revolute_horizontal"


def box_iou(a: Box | None, b: Box | None) -> float:
    """Intersection over union of two (x0, y0, x1, y1) boxes by area; 0 if either is missing or empty."""
    if a is None or b is None:
        return 0.0
    iw = min(a[2], b[2]) - max(a[0], b[0])
    ih = min(a[3], b[3]) - max(a[1], b[1])
    inter = max(iw, 0.0) * max(ih, 0.0)
    area_a = max(a[2] - a[0], 0.0) * max(a[3] - a[1], 0.0)
    area_b = max(b[2] - b[0], 0.0) * max(b[3] - b[1], 0.0)
    union = area_a + area_b - inter
    return float(inter / union) if union > 0 else 0.0


def box_cover(inner: Box, outer: Box) -> float:
    """Fraction of ``inner``'s area lying inside ``outer`` (0 for an empty ``inner``)."""
    iw = min(inner[2], outer[2]) - max(inner[0], outer[0])
    ih = min(inner[3], outer[3]) - max(inner[1], outer[1])
    area = max(inner[2] - inner[0], 0.0) * max(inner[3] - inner[1], 0.0)
    return float(max(iw, 0.0) * max(ih, 0.0) / area) if area > 0 else 0.0


def photo_box_to_projection(box: Box, render_to_photo: Any) -> Box:
    """Map a box drawn on the photo into the pose projection: inverse affine of its 4 corners, then their box."""
    A = np.vstack([np.asarray(render_to_photo, float).reshape(2, 3), [0.0, 0.0, 1.0]])
    x0, y0, x1, y1 = box
    corners = np.array([[x0, y0, 1], [x1, y0, 1], [x1, y1, 1], [x0, y1, 1]], float)
    q = corners @ np.linalg.inv(A).T
    return (float(q[:, 0].min()), float(q[:, 1].min()), float(q[:, 0].max()), float(q[:, 1].max()))


def load_box_labels(path: str | Path, to_projection: bool = True) -> BoxLabels:
    """Read the label JSON (format in the module docstring); boxes must have x0 < x1 and y0 < y1.

    ``to_projection`` maps the boxes of frames that carry ``render_to_photo`` into the pose projection
    (what the evaluation compares with); False keeps them exactly as drawn on the photo."""
    doc = json.loads(Path(path).read_text())
    w, h = doc.get("image_size", (640, 480))
    frames: dict[str, FrameLabels] = {}
    for fid, fr in doc["frames"].items():
        fronts = {k: _check_box(v, f"{fid}/{k}") for k, v in fr.get("fronts", {}).items()}
        ignore = tuple(_check_box(b, f"{fid}/ignore") for b in fr.get("ignore", []))
        A = fr.get("render_to_photo")
        if A is not None:
            A = tuple(tuple(float(x) for x in row) for row in A)
            if np.asarray(A).shape != (2, 3):
                raise ValueError(f"{fid}/render_to_photo must be a 2x3 affine, got {fr['render_to_photo']}")
            if to_projection:  # clipped like a part's projection: what lies outside the image is not seen
                fronts = {k: _clip(photo_box_to_projection(b, A), w, h) for k, b in fronts.items()}
                ignore = tuple(_clip(photo_box_to_projection(b, A), w, h) for b in ignore)
        frames[fid] = FrameLabels(fronts, ignore, A)
    return BoxLabels(frames, (int(w), int(h)))


def _clip(b: Box, width: int, height: int) -> Box:
    return (max(b[0], 0.0), max(b[1], 0.0), min(b[2], width - 1.0), min(b[3], height - 1.0))


def _check_box(b: Any, where: str) -> Box:
    x0, y0, x1, y1 = (float(v) for v in b)
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"label box {where} is empty or inverted: {list(b)}")
    return (x0, y0, x1, y1)


def load_predicted_parts(result_dir: str | Path, max_vertices: int = 20000) -> list[PredictedPart]:
    """Movable parts of a ``react3d convert`` output folder (``scene.json`` + ``meshes/<object>/part.ply``).

    Large parts are subsampled to ``max_vertices`` (evenly, deterministic): a box needs extremes, not density."""
    result_dir = Path(result_dir)
    manifest = json.loads((result_dir / "scene.json").read_text())
    parts = []
    for obj in manifest.get("objects", []):
        mesh = load_mesh(result_dir / obj["part_mesh"])
        v = mesh.vertices
        if len(v) > max_vertices:
            v = v[np.linspace(0, len(v) - 1, max_vertices).astype(np.int64)]
        art = obj.get("articulation") or {}
        axis = art.get("axis")
        parts.append(PredictedPart(obj["object_id"], v, str(art.get("joint_type", "unknown")),
                                   tuple(float(a) for a in axis) if axis is not None else None))
    return parts


def project_visible(vertices: np.ndarray, frame: Frame, depth: np.ndarray | None, depth_tol: float = 0.03,
                    width: int | None = None, height: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (N, 2) of ``vertices`` in ``frame`` and which of them the camera sees.

    Seen: in front of the camera, inside the image, and not behind the rendered scan surface ``depth``
    (z-depth, 0 = no surface) by more than ``depth_tol`` metres; ``depth=None`` skips the occlusion test."""
    intr = frame.intrinsics
    W, H = width or intr.width, height or intr.height
    K = intr.scaled(W, H).K if (W, H) != (intr.width, intr.height) else intr.K
    w2c = frame.w2c
    pc = np.asarray(vertices, float).reshape(-1, 3) @ w2c[:3, :3].T + w2c[:3, 3]
    z = pc[:, 2]
    front = z > 1e-3
    zs = np.where(front, z, 1.0)
    uv = np.stack([K[0, 0] * pc[:, 0] / zs + K[0, 2], K[1, 1] * pc[:, 1] / zs + K[1, 2]], -1)
    ui, vi = np.rint(uv[:, 0]).astype(np.int64), np.rint(uv[:, 1]).astype(np.int64)
    seen = front & (ui >= 0) & (ui < W) & (vi >= 0) & (vi < H)
    if depth is not None:
        d = depth[vi[seen], ui[seen]]
        seen[seen] = (d <= 0) | (z[seen] <= d + depth_tol)
    return uv, seen


def visible_box(vertices: np.ndarray, frame: Frame, depth: np.ndarray | None, depth_tol: float = 0.03,
                min_visible: int = 20, width: int | None = None, height: int | None = None) -> Box | None:
    """Box of the projection of ``vertices`` that the camera of ``frame`` actually sees (``project_visible``),
    or None when fewer than ``min_visible`` vertices are seen."""
    uv, seen = project_visible(vertices, frame, depth, depth_tol, width, height)
    if int(seen.sum()) < min_visible:
        return None
    q = uv[seen]
    return (float(q[:, 0].min()), float(q[:, 1].min()), float(q[:, 0].max()), float(q[:, 1].max()))


def part_boxes(parts: list[PredictedPart], scene: SceneInput, labels: BoxLabels, scan: TriMesh | None = None,
               depth_tol: float = 0.03, min_visible: int = 20) -> dict[str, dict[str, Box | None]]:
    """Visible box of every part in every labelled frame, in label pixels: {object_id: {frame_id: box}}.

    The scan mesh (default: ``scene.mesh_path``) is rendered once per labelled frame for the occlusion test."""
    from ..raster import Rasterizer

    scan = scan if scan is not None else load_mesh(scene.mesh_path)
    rast = Rasterizer(scan)
    W, H = labels.image_size
    out: dict[str, dict[str, Box | None]] = {p.object_id: {} for p in parts}
    for fid in labels.frames:
        frame = scene.frame(fid)
        intr = frame.intrinsics if (frame.intrinsics.width, frame.intrinsics.height) == (W, H) else frame.intrinsics.scaled(W, H)
        depth = rast.render_frame(frame, intr).depth
        for p in parts:
            out[p.object_id][fid] = visible_box(p.vertices, frame, depth, depth_tol, min_visible, W, H)
    return out


def match_boxes(boxes: dict[str, dict[str, Box | None]], labels: BoxLabels,
                iou_threshold: float = 0.5, ignore_cover: float = 0.5) -> BoxLabelReport:
    """One-to-one matching of parts to labelled fronts from precomputed visible boxes (pure, no rendering).

    ``boxes`` is {part_id: {frame_id: box or None}} in label pixels (what ``part_boxes`` returns)."""
    part_ids = list(boxes)
    front_ids = labels.front_ids
    labelled_in = {f: [fid for fid, fl in labels.frames.items() if f in fl.fronts] for f in front_ids}
    S = np.zeros((len(part_ids), len(front_ids)))
    per_frame: dict[tuple[int, int], dict[str, float]] = {}
    for i, pid in enumerate(part_ids):
        for j, f in enumerate(front_ids):
            ious = {fid: box_iou(boxes[pid].get(fid), labels.frames[fid].fronts[f]) for fid in labelled_in[f]}
            per_frame[i, j] = ious
            S[i, j] = float(np.mean(list(ious.values()))) if ious else 0.0
    assigned: dict[int, int] = {}
    if S.size:
        rows, cols = linear_sum_assignment(-S)
        assigned = {int(c): int(r) for r, c in zip(rows, cols) if S[r, c] > 0}
    matched = {j: i for j, i in assigned.items() if S[i, j] >= iou_threshold}
    fronts = []
    for j, f in enumerate(front_ids):
        if j in assigned:  # below the threshold the assigned part is still reported (found=False) for diagnosis
            i = assigned[j]
            other = float(np.delete(S[i], j).max()) if len(front_ids) > 1 else 0.0
            fronts.append(FrontResult(f, j in matched, part_ids[i], float(S[i, j]), other, per_frame_iou=per_frame[i, j]))
        else:
            fronts.append(FrontResult(f, False))
    found_parts = {part_ids[i] for i in matched.values()}
    false_parts, ignored, unseen = [], [], []
    for pid in part_ids:
        if pid in found_parts:
            continue
        seen = {fid: b for fid, b in boxes[pid].items() if b is not None and fid in labels.frames}
        if not seen:
            unseen.append(pid)
        elif any(box_cover(b, ig) >= ignore_cover for fid, b in seen.items() for ig in labels.frames[fid].ignore):
            ignored.append(pid)
        else:
            false_parts.append(pid)
    pb = {pid: {fid: [round(x, 1) for x in b] for fid, b in fb.items() if b is not None} for pid, fb in boxes.items()}
    return BoxLabelReport(fronts, false_parts, ignored, unseen, len(part_ids), iou_threshold, pb)


def evaluate_box_labels(result_dir: str | Path, scene: SceneInput, labels: BoxLabels | str | Path,
                        iou_threshold: float = 0.5, depth_tol: float = 0.03, ignore_cover: float = 0.5,
                        min_visible: int = 20) -> BoxLabelReport:
    """Score a ``react3d convert`` output folder against box labels of its scene (see module docstring).

    A front is found when its Hungarian-matched part has mean box IoU >= ``iou_threshold`` (0.5)."""
    labels = labels if isinstance(labels, BoxLabels) else load_box_labels(labels)
    parts = load_predicted_parts(result_dir)
    boxes = part_boxes(parts, scene, labels, depth_tol=depth_tol, min_visible=min_visible)
    report = match_boxes(boxes, labels, iou_threshold, ignore_cover)
    by_id = {p.object_id: p for p in parts}
    for fr in report.fronts:  # joints of every assigned part, found or not
        if fr.part is not None:
            fr.joint_type = by_id[fr.part].joint_type
            fr.joint_class = by_id[fr.part].joint_class
    return report
