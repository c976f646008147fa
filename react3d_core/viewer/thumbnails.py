"""Thumbnails of a part in its source views: the RGB frame cropped around the part, its outline drawn.

The outline is the part's occlusion-aware silhouette: the scan mesh is rendered in that view and the
pixels whose visible face belongs to the part are kept, so what the user sees is what the mask saw.
"""

from __future__ import annotations

import base64

import cv2
import numpy as np

from ..data.frames import SceneInput
from ..data.mesh import TriMesh
from ..raster import Rasterizer
from ..scene_io.images import frame_rgb


def part_face_mask(mesh: TriMesh, vertex_ids: np.ndarray) -> np.ndarray:
    """Boolean per face: all three vertices belong to the part."""
    inside = np.zeros(mesh.n_vertices, bool)
    inside[np.asarray(vertex_ids, np.int64)] = True
    return inside[mesh.faces].all(1)


def thumbnail(
    rgb: np.ndarray, silhouette: np.ndarray, size: int = 160, margin: float = 0.25, color: tuple[int, int, int] = (255, 140, 0)
) -> np.ndarray | None:
    """Crop around the silhouette (with margin), draw its outline; None if the part is not visible."""
    ys, xs = np.nonzero(silhouette)
    if len(xs) == 0:
        return None
    h, w = silhouette.shape
    x0, x1, y0, y1 = xs.min(), xs.max(), ys.min(), ys.max()
    side = max(x1 - x0, y1 - y0) * (1 + 2 * margin) + 8
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    a0, a1 = int(max(0, cx - side / 2)), int(min(w, cx + side / 2))
    b0, b1 = int(max(0, cy - side / 2)), int(min(h, cy + side / 2))
    img = rgb.copy()
    contours, _ = cv2.findContours(silhouette.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    tint = img[silhouette].astype(float) * 0.6 + np.array(color, float) * 0.4
    img[silhouette] = tint.astype(np.uint8)
    cv2.drawContours(img, contours, -1, color, max(1, w // 320))
    crop = img[b0:b1, a0:a1]
    s = size / max(crop.shape[:2])
    return cv2.resize(crop, (max(1, round(crop.shape[1] * s)), max(1, round(crop.shape[0] * s))), interpolation=cv2.INTER_AREA)


def to_data_uri(img: np.ndarray, quality: int = 85) -> str:
    ok, buf = cv2.imencode(".jpg", cv2.cvtColor(img, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise ValueError("JPEG encoding failed")
    return "data:image/jpeg;base64," + base64.b64encode(buf.tobytes()).decode("ascii")


def part_thumbnails(
    scene: SceneInput,
    mesh: TriMesh,
    parts: dict[str, tuple[np.ndarray, list[str]]],
    width: int = 480,
    per_part: int = 3,
    rasterizer: Rasterizer | None = None,
) -> dict[str, list[str]]:
    """``parts``: object id -> (vertex ids into ``mesh``, frame ids best first). Returns data URIs.

    Frames are rendered once each even when several parts share them.
    """
    ras = rasterizer or Rasterizer(mesh)
    masks = {oid: part_face_mask(mesh, vids) for oid, (vids, _) in parts.items()}
    wanted: dict[str, list[str]] = {}
    for oid, (_, fids) in parts.items():
        for fid in fids[:per_part]:
            wanted.setdefault(fid, []).append(oid)
    out: dict[str, list[str]] = {oid: [] for oid in parts}
    frames = {f.frame_id: f for f in scene.frames}
    for fid, oids in wanted.items():
        if fid not in frames:
            continue
        f = frames[fid]
        intr = f.intrinsics.scaled(width, round(f.intrinsics.height * width / f.intrinsics.width))
        r = ras.render_frame(f, intr)
        rgb = cv2.resize(frame_rgb(f), (intr.width, intr.height), interpolation=cv2.INTER_AREA)
        valid = r.face_ids >= 0
        for oid in oids:
            sil = np.zeros_like(valid)
            sil[valid] = masks[oid][r.face_ids[valid]]
            t = thumbnail(rgb, sil)
            if t is not None:
                out[oid].append(to_data_uri(t))
    return out
