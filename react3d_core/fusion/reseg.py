"""Re-segmentation: point prompts from a proposal's silhouette in its best view -> mask -> scan faces.

Why: fused proposals are only as good as the co-occurrence graph (ragged, sometimes a fragment
of the part); one clean mask in the best view, back-projected on the full-resolution scan, gives
sharp part boundaries. Faces that view cannot see come from the other top-k views or the proposal.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from ..config import PipelineConfig
from ..data.frames import Frame
from ..data.masks import Mask2D
from ..data.mesh import TriMesh
from ..data.parts import TopView
from ..errors import InputError
from ..perception.interfaces import PointPromptSegmenter
from ..camera import project, scaled_px
from ..raster import Rasterizer
from ..raster.rasterizer import RasterResult
from .connectivity import largest_component
from .lift import erode, filled, not_through


def point_prompts(silhouette: np.ndarray, n_pos: int = 3, n_neg: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Positive points deep inside the silhouette (distance-transform peaks, spread apart) and
    negative points just outside its bounding box (left, right, above, below). (N,2) px, labels 1/0."""
    h, w = silhouette.shape
    sil = silhouette.astype(np.uint8)
    dt = cv2.distanceTransform(np.pad(sil, 1), cv2.DIST_L2, 5)[1:-1, 1:-1]
    pts, lab = [], []
    work = dt.copy()
    for _ in range(n_pos):
        y, x = np.unravel_index(int(np.argmax(work)), work.shape)
        if work[y, x] <= 0:
            break
        pts.append((x, y))
        lab.append(1)
        r = max(2, int(dt[y, x]))
        cv2.circle(work, (int(x), int(y)), r, 0, -1)
    ys, xs = np.nonzero(silhouette)
    if len(xs):
        x0, x1, y0, y1 = xs.min(), xs.max(), ys.min(), ys.max()
        mx, my = max(3, (x1 - x0) // 8), max(3, (y1 - y0) // 8)
        cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
        cand = [(x0 - mx, cy), (x1 + mx, cy), (cx, y0 - my), (cx, y1 + my)][:n_neg]
        for x, y in cand:
            if 0 <= x < w and 0 <= y < h and not silhouette[y, x]:
                pts.append((x, y))
                lab.append(0)
    return np.asarray(pts, float).reshape(-1, 2), np.asarray(lab, np.int64)


def _image(frame: Frame) -> np.ndarray:
    """The RGB image for the point segmenter (a black image when the file is unreadable: the
    oracle and heuristic backends do not look at it)."""
    from ..scene_io.images import frame_rgb

    try:
        return frame_rgb(frame)
    except InputError:
        return np.zeros((frame.intrinsics.height, frame.intrinsics.width, 3), np.uint8)


def hidden_behind(mesh: TriMesh, centroids: np.ndarray, K: np.ndarray, w2c: np.ndarray, raster: RasterResult,
                  mask: np.ndarray, slab_m: float) -> np.ndarray:
    """Faces whose centroid projects inside ``mask`` (``K`` for the buffer's pixels) and lies at most
    ``slab_m`` behind the visible surface there (the back and edges of a door or drawer front).
    Only faces within the 3D box of the visible masked surface (+ slab) are projected."""
    h, w = mask.shape
    f = raster.face_ids[mask]
    f = f[f >= 0]
    if not len(f):
        return np.zeros(0, np.int64)
    vis = centroids[np.unique(f)]
    lo, hi = vis.min(0) - slab_m - 0.01, vis.max(0) + slab_m + 0.01
    idx = np.nonzero(np.all((centroids >= lo) & (centroids <= hi), 1))[0]
    uv, z = project(centroids[idx], K, w2c)
    ok = (z > 0) & np.all(np.isfinite(uv), 1)
    idx, uv, z = idx[ok], uv[ok], z[ok]
    ui, vi = np.round(uv[:, 0]).astype(np.int64), np.round(uv[:, 1]).astype(np.int64)
    ok = (ui >= 0) & (ui < w) & (vi >= 0) & (vi < h)
    idx, ui, vi, z = idx[ok], ui[ok], vi[ok], z[ok]
    inside = mask[vi, ui]
    idx, ui, vi, z = idx[inside], ui[inside], vi[inside], z[inside]
    surf = raster.depth[vi, ui]
    return idx[(surf > 0) & (z <= surf + slab_m)]


def render_crop(rasterizer: Rasterizer, frame: Frame, box: tuple[int, int, int, int]) -> tuple[RasterResult, np.ndarray]:
    """Full-resolution buffers of the pixel box (x0, y0, x1, y1) only, and the crop's K."""
    x0, y0, x1, y1 = box
    K = frame.intrinsics.K.copy()
    K[0, 2] -= x0
    K[1, 2] -= y0
    return rasterizer.render(K, frame.c2w, x1 - x0, y1 - y0, frame.frame_id), K


def resegment(
    frame: Frame,
    mesh: TriMesh,
    wfaces: np.ndarray,
    centroids: np.ndarray,
    proposal_faces: np.ndarray,
    top_views: Sequence[TopView],
    buffers: dict[str, RasterResult],
    point_segmenter: PointPromptSegmenter,
    rasterizer: Rasterizer,
    config: PipelineConfig,
) -> tuple[np.ndarray, Mask2D]:
    """Scan faces of the part segmented in ``frame`` (its best view), and the mask used.

    Prompts come from the proposal's silhouette in the working-resolution buffer; the mask is
    back-projected at full resolution (only its bounding box is rendered): visible faces under it,
    faces hidden right behind it (slab), and faces this view cannot see under the other top-k
    masks; then the largest connected component (+ attached handles). Pixels that see through the
    front (:func:`.lift.through_pixels`) are left out of every mask.
    """
    W, H = frame.intrinsics.width, frame.intrinsics.height
    ids_w = buffers[frame.frame_id].face_ids
    in_prop = np.zeros(mesh.n_faces + 1, bool)
    in_prop[proposal_faces] = True
    sil = in_prop[ids_w]  # -1 -> last slot (False)
    pts, lab = point_prompts(sil)
    sx, sy = W / ids_w.shape[1], H / ids_w.shape[0]
    pts = np.clip((pts + 0.5) * [sx, sy] - 0.5, 0, [W - 1, H - 1])
    mask = point_segmenter.segment_points(frame, _image(frame), pts, lab) if len(pts) else None
    if mask is None or mask.area == 0:
        mask = top_views[0].mask
    m = erode(filled(mask.mask, (H, W), config), max(1, scaled_px(config.fusion.erode_px, W) // 2))
    ys, xs = np.nonzero(m.any(1))[0], np.nonzero(m.any(0))[0]
    if not len(ys):
        return np.zeros(0, np.int64), mask
    box = (int(xs[0]), int(ys[0]), int(xs[-1]) + 1, int(ys[-1]) + 1)
    crop, Kc = render_crop(rasterizer, frame, box)
    mc = not_through(m[box[1] : box[3], box[0] : box[2]], crop.depth, config, W,
                     (box[1] == 0, box[3] == H, box[0] == 0, box[2] == W))
    vis = crop.face_ids[mc]
    faces = [np.unique(vis[vis >= 0])]
    faces.append(hidden_behind(mesh, centroids, Kc, frame.w2c, crop, mc, config.clip.keep_behind_m))
    seen = np.zeros(mesh.n_faces + 1, bool)
    seen[ids_w] = True
    seen[crop.face_ids] = True
    seen[-1] = False
    for tv in top_views:  # faces hidden from the segmenting view, seen under the part's other masks
        if tv.frame_id == frame.frame_id or tv.mask is None or tv.frame_id not in buffers:
            continue
        buf = buffers[tv.frame_id]
        ids = buf.face_ids
        mm = erode(filled(tv.mask.mask, ids.shape, config, buf.depth), scaled_px(config.fusion.erode_px, ids.shape[1]))
        f = ids[mm]
        f = f[f >= 0]
        faces.append(f[~seen[f]])
    allf = np.unique(np.concatenate(faces)).astype(np.int64)
    if not len(allf):
        return allf, mask
    return largest_component(mesh, wfaces, allf, config.fusion.attach_m, config.fusion.keep_share), mask
