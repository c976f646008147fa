"""Render a :class:`SynthLayout` and write it as a ScanNet++ iPhone scene with Articulate3D ground truth.

Layout (docs/CONTRACTS.md section 2)::

    scans/mesh_aligned_0.05.ply, iphone/pose_intrinsic_imu.json, iphone/rgb/frame_%06d.jpg,
    iphone/depth.bin (per-frame LZ4), iphone/gt_part_ids/frame_%06d.png (uint16, partId + 1),
    articulate3d/<scene_id>_{parts,artic}.json, synth_meta.json

The folder appears whole or not at all (built in a temporary sibling and renamed).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..atomic import atomic_dir, write_json
from ..data.mesh import TriMesh, save_mesh
from ..data.parts import OBB
from ..ground_truth.articulate3d import GroundTruth, GTPart, write_articulate3d
from ..raster import Rasterizer
from ..scene_io.depth_bin import write_depth_bin
from .camera_path import camera_walk
from .depth_effects import DEPTH_DROPOUT, dark_dropout, glass_returns, is_glass, linear_albedo
from .materials import GLASS, REALISM, GlassLayer, PhotoSettings, render_photo, scene_lights
from .observed import keep_faces, observed_faces
from .procedural import SynthLayout
from .remesh import (LASER_DECIMATION, LASER_VOXEL, MESH_KINDS, TRANSFER_RADIUS, TSDF_VOXEL, TsdfFuser, decimate,
                     decimate_to, laser_depth, transfer_labels, transfer_parts)
from .render import DEPTH_SIZE, RGB_SIZE, RayCaster, base_intrinsics, scale_K, sensor_depth

# 2: URDF sources keep only observed surfaces; 3: photo realism (default) and laser / TSDF scan meshes;
# 4: scene-synthesizer kitchens drop objects stacked on an earlier one (from_scene_synthesizer.py)
GENERATOR_VERSION = "4"


def _gt_parts(layout: SynthLayout, keep: np.ndarray | None = None) -> tuple[list[GTPart], np.ndarray, list[dict]]:
    """GT parts (movable, then handles, then static carcasses), the face -> partId table and meta rows.

    ``keep`` (face ids of ``layout.mesh``): the GT indexes the sub-mesh of these faces (the written
    scan without its glass panes); the face -> partId table stays that of the whole mesh."""
    mesh, keys = layout.mesh, layout.face_keys
    key_pid: dict[str, int] = {}
    order: list[tuple[str, str, object]] = []
    for p in layout.parts:
        order.append((p.key, p.label, p))
    for p in layout.parts:
        if p.handle_key:
            order.append((p.handle_key, p.label + ".handle", None))
    for k, label in layout.statics.items():
        order.append((k, f"{label}.{k}" if not k.startswith(label) else k, None))
    for i, (k, _, _) in enumerate(order):
        key_pid[k] = i
    lut = np.full(len(layout.key_ids) + 1, -1, np.int64)
    for k, kid in layout.key_ids.items():
        if k in key_pid:
            lut[kid] = key_pid[k]
    face_pid = lut[keys]  # keys == -1 index the trailing -1 entry
    on_mesh = face_pid
    if keep is not None:
        mesh, _ = mesh.submesh(keep)
        on_mesh = face_pid[keep]
    parts, meta = [], []
    for pid, (k, label, spec) in enumerate(order):
        tri = np.flatnonzero(on_mesh == pid)
        vert = np.unique(mesh.faces[tri].ravel())
        art = spec.articulation if spec is not None else None  # type: ignore[union-attr]
        base = [key_pid[spec.parent_key]] if spec is not None and spec.parent_key in key_pid else []  # type: ignore[union-attr]
        parts.append(GTPart(pid, label, tri, vert, art, base))
        if spec is not None:
            meta.append({"part_id": pid, "label": label, "kind": spec.kind, "type": art.joint_type,  # type: ignore[union-attr]
                         "handle": spec.handle_key is not None,  # type: ignore[union-attr]
                         "handle_part_id": key_pid.get(spec.handle_key) if spec.handle_key else None,  # type: ignore[union-attr]
                         "parent_part_id": base[0] if base else None,
                         "interior_depth": spec.interior_depth, "n_faces": int(len(tri))})  # type: ignore[union-attr]
    return parts, face_pid, meta


def _ray_norm(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """Per pixel the length of the camera ray with z = 1 (ray length = z-depth x this)."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
    return np.sqrt(((u - K[0, 2]) / K[0, 0]) ** 2 + ((v - K[1, 2]) / K[1, 1]) ** 2 + 1.0).astype(np.float32)


def _remeshed_gt(layout: SynthLayout, fuser: TsdfFuser, kind: str, gt_parts: list[GTPart], face_pid: np.ndarray,
                 meta: list[dict], keep: float = 1.0, keep_empty: bool = False) -> tuple[TriMesh, list[GTPart], list[dict], dict]:
    """The fused scan mesh (quadric-decimated to ``keep`` of its faces), the GT moved onto it, the meta
    rows of the parts kept and mesh statistics. ``keep_empty``: movable parts left without scan surface
    stay in the GT (they carry their box)."""
    new = fuser.mesh()
    if kind == "laser":
        new = decimate(new, LASER_DECIMATION)
    fused_faces = new.n_faces
    if keep < 1:
        new = decimate_to(new, keep)
    tr = transfer_labels(layout.mesh, face_pid, new)
    if kind == "laser":  # a laser scan is coloured from registered photos: the clean colour at the surface
        new = TriMesh(new.vertices, new.faces, tr.colors)
    parts, dropped = transfer_parts(gt_parts, tr, keep_empty_movable=keep_empty)
    n_faces = {p.part_id: len(p.tri_indices) for p in parts}
    rows = []
    for r in meta:
        if r["part_id"] not in n_faces:
            continue
        rows.append({**r, "n_faces": n_faces[r["part_id"]],
                     "handle_part_id": r["handle_part_id"] if r["handle_part_id"] in n_faces else None,
                     "handle": r["handle_part_id"] in n_faces,
                     "parent_part_id": r["parent_part_id"] if r["parent_part_id"] in n_faces else None})
    stats = {"kind": kind, "voxel": LASER_VOXEL if kind == "laser" else TSDF_VOXEL,
             "decimation": LASER_DECIMATION if kind == "laser" else 0.0, "kept_share": keep, "fused_faces": fused_faces,
             "clean_faces": layout.mesh.n_faces, "clean_vertices": layout.mesh.n_vertices,
             "transfer_radius": TRANSFER_RADIUS, "labelled_vertices": float((tr.vertex_label >= 0).mean()),
             "median_distance_to_clean": float(np.median(tr.distance)) if len(tr.distance) else None,
             "dropped_parts": dropped}
    return new, parts, rows, stats


def part_box(points: np.ndarray) -> OBB:
    """Upright box of a part's points (z up; the horizontal sides from the minimum-area rectangle of
    their footprint), sides sorted longest first: the true box of a front, a lid or a porthole door."""
    import cv2

    p = np.asarray(points, float)
    (cx, cy), (w, h), ang = cv2.minAreaRect(p[:, :2].astype(np.float32))
    a = np.radians(ang)
    u, v = np.array([np.cos(a), np.sin(a), 0.0]), np.array([-np.sin(a), np.cos(a), 0.0])
    z0, z1 = float(p[:, 2].min()), float(p[:, 2].max())
    # refit the centre and extents in float64 along the rectangle's sides
    pu, pv = p @ u, p @ v
    axes = [u, v, np.array([0.0, 0.0, 1.0])]
    lo = np.array([pu.min(), pv.min(), z0])
    hi = np.array([pu.max(), pv.max(), z1])
    ext = hi - lo
    centre = np.stack(axes, 1) @ ((lo + hi) / 2)
    order = np.argsort(-ext, kind="stable")
    R = np.stack([axes[k] for k in order], 1)
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple(centre), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))


def _face_samples(mesh: TriMesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Four points per face (centroid and halfway from it to each corner) and each point's area share."""
    tri = mesh.vertices[mesh.faces[faces]]
    c = tri.mean(1, keepdims=True)
    pts = np.concatenate([c, 0.5 * (c + tri)], 1).reshape(-1, 3)
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return pts, np.repeat(area / 4.0, 4)


def _boxes_and_coverage(layout: SynthLayout, face_pid: np.ndarray, parts: list[GTPart], scan: TriMesh | None,
                        seen: np.ndarray, glass: np.ndarray) -> dict[int, tuple[OBB, float]]:
    """Per movable GT part: its true box (its faces and its children's in the generated mesh) and the
    share of its observed opaque surface (faces any frame saw, glass left out; all its opaque faces if
    no frame saw it) that lies within the transfer radius of the scan mesh (``scan`` None: the written
    mesh is the generated one, share 1)."""
    mesh = layout.mesh
    out: dict[int, tuple[OBB, float]] = {}
    dist = Rasterizer(scan) if scan is not None and scan.n_faces else None
    for p in parts:
        if p.articulation is None:
            continue
        kids = [q.part_id for q in parts if q.articulation is None and q.label.startswith(p.label + ".")]
        own = np.isin(face_pid, [p.part_id] + kids)
        box = part_box(mesh.vertices[np.unique(mesh.faces[own].ravel())])
        obs = np.flatnonzero(own & seen & ~glass)
        if not len(obs):  # no frame saw it: its whole opaque surface
            obs = np.flatnonzero(own & ~glass)
        pts, w = _face_samples(mesh, obs)
        if scan is None:
            cov = 1.0
        elif dist is None:
            cov = 0.0
        else:
            cov = float(w[dist.distance(pts.astype(np.float32)) <= TRANSFER_RADIUS].sum() / w.sum())
        out[p.part_id] = (box, cov)
    return out


@dataclass
class _SeeThrough:
    """Ray casts past glass panes: the scene without its glass faces, ids mapped back to the whole mesh."""

    caster: RayCaster
    ids: np.ndarray  # opaque-mesh face -> whole-mesh face

    @classmethod
    def of(cls, mesh: TriMesh, glass: np.ndarray) -> "_SeeThrough":
        keep = np.flatnonzero(~glass)
        sub, _ = mesh.submesh(keep)
        return cls(RayCaster(sub), keep)

    def behind(self, front: dict[str, np.ndarray], glass_px: np.ndarray, K: np.ndarray, c2w: np.ndarray,
               width: int, height: int) -> dict[str, np.ndarray]:
        """``front`` where no glass is hit, else the first opaque surface behind the pane."""
        back = self.caster.cast(K, c2w, width, height)
        back["face"] = np.where(back["face"] >= 0, self.ids[np.maximum(back["face"], 0)], -1)
        out = {}
        for k, v in front.items():
            sel = glass_px if v.ndim == 2 else glass_px[..., None]
            out[k] = np.where(sel, back[k], v)
        return out


def write_synthetic(layout: SynthLayout, out_dir: str | Path, n_frames: int, seed: int, source: str,
                    scene_id: str | None = None, room_depths: list[float] | None = None, mesh: str = "clean",
                    realism: str = "photo", misregister: tuple[float, float] = (0.0, 0.0),
                    depth_dropout: str = "none", decimate: float = 1.0) -> Path:
    """Render ``n_frames`` views of ``layout`` and write the scene folder; returns ``out_dir``.

    ``mesh``: the written scan mesh, ``clean`` (the generated geometry), ``laser`` or ``tsdf`` (re-made
    like a real scan, GT transferred; see :mod:`.remesh`); ``decimate``: share of that laser / TSDF
    mesh's faces kept by quadric decimation before the GT is transferred (1: as made; a user's exported
    scan is often decimated). ``realism``: ``photo`` (materials, lights,
    exposure, blur; :mod:`.materials`) or ``plain`` (flat shading, the generator-version-2 images).
    ``misregister``: colour shifted by (dx, dy) RGB pixels against depth and poses (photo only).
    ``depth_dropout``: ``dark`` drops depth on dark and glossy surfaces like a ToF sensor, in the depth
    frames and in the range images a laser / TSDF mesh is fused from (:mod:`.depth_effects`).
    Glass faces (material ``GLASS``) are seen through in colour and depth and left out of a clean
    written mesh. Scenes with glass, depth dropout or ``layout.gt_boxes`` carry each movable part's
    true box and scan coverage in the GT (parts without scan surface are kept).
    """
    out_dir = Path(out_dir)
    if n_frames < 1:
        raise ValueError("n_frames must be >= 1")
    if mesh not in MESH_KINDS:
        raise ValueError(f"unknown mesh {mesh!r}; choose from {', '.join(MESH_KINDS)}")
    if realism not in REALISM:
        raise ValueError(f"unknown realism {realism!r}; choose from {', '.join(REALISM)}")
    if not 0 < decimate <= 1:
        raise ValueError(f"decimate is the share of faces kept, in (0, 1]; got {decimate}")
    if decimate < 1 and mesh == "clean":
        raise ValueError("decimate needs mesh='laser' or 'tsdf' (the clean mesh's ground truth is its own faces)")
    if depth_dropout not in DEPTH_DROPOUT:
        raise ValueError(f"unknown depth_dropout {depth_dropout!r}; choose from {', '.join(DEPTH_DROPOUT)}")
    misregister = (float(misregister[0]), float(misregister[1]))
    if realism == "plain" and misregister != (0.0, 0.0):
        raise ValueError("misregister needs realism='photo'")
    rng = np.random.default_rng(seed + 1_000_003)
    scene_id = scene_id or out_dir.name
    K = base_intrinsics(rng)
    K_rgb, K_d = scale_K(K, RGB_SIZE[0]), scale_K(K, DEPTH_SIZE[0])
    if room_depths is None:
        room_depths = [5.0] * len(layout.runs)
    poses = camera_walk(layout.runs, n_frames, room_depths, rng)
    caster = RayCaster(layout.mesh)
    if layout.observed_only:
        dense = camera_walk(layout.runs, max(3 * n_frames, 240), room_depths, np.random.default_rng(seed + 7_777))
        layout = keep_faces(layout, observed_faces(caster, dense + poses, K))
        caster = RayCaster(layout.mesh)
    face_mat = layout.face_materials if layout.face_materials is not None else np.zeros(layout.mesh.n_faces, np.uint8)
    glass = face_mat == GLASS
    see = _SeeThrough.of(layout.mesh, glass) if glass.any() else None
    keep = np.flatnonzero(~glass) if see is not None and mesh == "clean" else None
    gt_parts, face_pid, meta = _gt_parts(layout, keep)
    with_boxes = see is not None or depth_dropout != "none" or layout.gt_boxes
    seen = np.zeros(layout.mesh.n_faces, bool)
    tint = (layout.face_colors if layout.face_colors is not None else np.full((layout.mesh.n_faces, 3), 255, np.uint8))
    albedo = linear_albedo(tint) if depth_dropout == "dark" else None
    photo = PhotoSettings(scene_lights(layout.room), misregister=misregister)
    fuser = {"clean": None, "laser": TsdfFuser(LASER_VOXEL, color=False, depth_scale=5000.0),
             "tsdf": TsdfFuser(TSDF_VOXEL, color=True)}[mesh]
    ray_norm = _ray_norm(K_rgb, *RGB_SIZE)
    with atomic_dir(out_dir) as tmp:
        (tmp / "iphone" / "rgb").mkdir(parents=True)
        (tmp / "iphone" / "gt_part_ids").mkdir(parents=True)
        depths, pose_json = [], {}
        for i, c2w in enumerate(poses):
            fid = f"frame_{i:06d}"
            hit = caster.cast(K_rgb, c2w, *RGB_SIZE)
            seen[hit["face"][hit["face"] >= 0]] = True
            # glass: shaded and ranged from what lies behind it; its own generators keep the others' draws
            shade, layer, z = hit, None, hit["depth"]
            fx_rng = np.random.default_rng([seed, i, 0x6A55]) if see is not None or albedo is not None else None
            if see is not None:
                gpx = is_glass(hit["face"], face_mat)
                shade = see.behind(hit, gpx, K_rgb, c2w, *RGB_SIZE)
                layer = GlassLayer(gpx, hit["normal"], hit["point"], tint[np.maximum(hit["face"], 0)].astype(np.float32) / 255.0)
                z = np.where(gpx & ~glass_returns(hit, gpx, fx_rng), shade["depth"], hit["depth"])
            if realism == "photo":  # its own per-frame generator: depth noise below stays that of 'plain'
                rgb = render_photo(shade, layout.mesh.faces, layout.mesh.colors, face_mat, photo,
                                   np.random.default_rng([seed, i, 0x5EED]), rng, layout.face_colors, glass=layer)
            else:
                rgb = caster.rgb(shade, rng)
                if layer is not None:
                    rgb = np.where(layer.mask[..., None], rgb * layer.tint, rgb).astype(np.uint8)
            if mesh == "laser":
                if albedo is not None:
                    z = np.where(dark_dropout(shade, albedo, face_mat, fx_rng), np.inf, z)
                fuser.add(laser_depth(z, ray_norm, np.random.default_rng([seed, i, 0x1A5E])), K_rgb, c2w)
            cv2.imwrite(str(tmp / "iphone" / "rgb" / f"{fid}.jpg"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR),
                        [cv2.IMWRITE_JPEG_QUALITY, 92])
            face = hit["face"]
            pid = np.where(face >= 0, face_pid[np.maximum(face, 0)] + 1, 0)
            cv2.imwrite(str(tmp / "iphone" / "gt_part_ids" / f"{fid}.png"), pid.astype(np.uint16))
            dhit = caster.cast(K_d, c2w, *DEPTH_SIZE)
            zd, dshade = dhit["depth"], dhit
            if see is not None:
                gpx = is_glass(dhit["face"], face_mat)
                dshade = see.behind(dhit, gpx, K_d, c2w, *DEPTH_SIZE)
                zd = np.where(gpx & ~glass_returns(dhit, gpx, fx_rng), dshade["depth"], dhit["depth"])
            depths.append(sensor_depth(zd, rng))
            if albedo is not None:
                depths[-1][dark_dropout(dshade, albedo, face_mat, fx_rng)] = 0.0
            if mesh == "tsdf":
                fuser.add(depths[-1], K_d, c2w, rgb)
            pose_json[fid] = {"intrinsic": K.tolist(), "aligned_pose": c2w.tolist(), "timestamp": round(i / 10.0, 3)}
        scan, mesh_stats = layout.mesh, {"kind": "clean"}
        if keep is not None:
            scan, _ = layout.mesh.submesh(keep)
            mesh_stats = {"kind": "clean", "glass_faces_left_out": int(glass.sum())}
        if fuser is not None:
            scan, gt_parts, meta, mesh_stats = _remeshed_gt(layout, fuser, mesh, gt_parts, face_pid, meta, decimate,
                                                           keep_empty=with_boxes)
        if with_boxes:
            boxes = _boxes_and_coverage(layout, face_pid, gt_parts, scan if fuser is not None else None, seen, glass)
            for p in gt_parts:
                if p.part_id in boxes:
                    p.obb, p.coverage = boxes[p.part_id]
            for r in meta:
                if r["part_id"] in boxes:
                    r["scan_coverage"] = round(boxes[r["part_id"]][1], 4)
        save_mesh(tmp / "scans" / "mesh_aligned_0.05.ply", scan)
        write_depth_bin(tmp / "iphone" / "depth.bin", depths, "per_frame")
        write_json(tmp / "iphone" / "pose_intrinsic_imu.json", pose_json)
        write_articulate3d(tmp / "articulate3d", GroundTruth(scene_id, gt_parts, scan.n_faces, scan.n_vertices))
        write_json(tmp / "synth_meta.json", {
            "generator_version": GENERATOR_VERSION, "source": source, "seed": seed, "kind": layout.kind,
            "scene_id": scene_id, "n_frames": len(poses), "room": list(layout.room),
            "faces": scan.n_faces, "vertices": scan.n_vertices, "parts": meta, "mesh": mesh_stats,
            "realism": realism, "misregister_px": list(misregister),
            **({"depth_dropout": depth_dropout} if depth_dropout != "none" else {}), **layout.extra})
    return out_dir
