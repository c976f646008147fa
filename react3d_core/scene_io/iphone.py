"""ScanNet++ iPhone layout (also what the synthetic scene writer produces).

``iphone/pose_intrinsic_imu.json`` keyed ``frame_%06d`` with ``aligned_pose`` (camera-to-world, OpenCV)
and ``intrinsic`` (for 1920x1440, rescaled here to the RGB size); RGB as ``iphone/rgb/*.jpg`` or
``iphone/rgb.mkv``; depth 256x192 in ``iphone/depth.bin`` (either encoding) or ``iphone/depth/*.png``;
mesh ``scans/mesh_aligned_0.05.ply``; optional ground-truth part ids ``iphone/gt_part_ids/*.png``.
"""

from __future__ import annotations

from pathlib import Path

from ..camera import K_SIZE
from ..data.frames import Frame, ImageRef, SceneInput
from ..errors import InputError
from .checks import (DEPTH_SIZE, check_depth_png, checked_intrinsics, checked_mesh, checked_pose, find_gt_dir,
                     read_json)
from .depth_bin import DepthBin
from .images import check_jpeg_complete, image_size
from .layout import Layout, LoadOptions

NAME = "scannetpp_iphone"


def detect(root: Path) -> bool:
    return (root / "iphone" / "pose_intrinsic_imu.json").is_file()


def load(root: Path, options: LoadOptions) -> SceneInput:
    ip = root / "iphone"
    meta_path = ip / "pose_intrinsic_imu.json"
    meta = read_json(meta_path)
    keys = sorted(k for k in meta if k.startswith("frame_"))
    if not keys:
        raise InputError(meta_path, "no frame_XXXXXX entries")
    mesh = checked_mesh(root / "scans" / "mesh_aligned_0.05.ply")
    mkv = ip / "rgb.mkv"
    use_mkv = not (ip / "rgb").is_dir() and mkv.is_file()
    if not use_mkv and not (ip / "rgb").is_dir():
        raise InputError(ip / "rgb", "RGB folder (or rgb.mkv) not found")
    first = mkv if use_mkv else ip / "rgb" / f"{keys[0]}.jpg"
    if not first.is_file():
        raise InputError(first, "image file not found")
    w, h = image_size(first)
    depth_bin = ip / "depth.bin"
    depth_kind = None
    if depth_bin.is_file():
        db = DepthBin(depth_bin)
        if len(db) != len(keys):
            raise InputError(depth_bin, f"holds {len(db)} depth frames but {meta_path.name} lists {len(keys)} frames")
        depth_kind = "depth_bin_lz4" if db.encoding == "per_frame" else "depth_bin_deflate_stream"
    notes: list[str] = []
    frames = []
    for n, key in enumerate(keys):
        entry = meta[key]
        if not isinstance(entry, dict) or "intrinsic" not in entry or "aligned_pose" not in entry:
            raise InputError(meta_path, f"{key}: missing 'intrinsic' or 'aligned_pose'")
        K = checked_intrinsics(meta_path, key, entry["intrinsic"], *K_SIZE).scaled(w, h)
        pose = checked_pose(meta_path, key, entry["aligned_pose"])
        if use_mkv:
            rgb = ImageRef(path=mkv, kind="mkv", index=n)
        else:
            p = ip / "rgb" / f"{key}.jpg"
            if not p.is_file():
                raise InputError(p, "image file not found")
            check_jpeg_complete(p)  # per frame at load: 4 KB read; libjpeg would only warn later
            rgb = ImageRef(path=p, kind="jpg")
        if depth_kind:
            depth = ImageRef(path=depth_bin, kind=depth_kind, index=n)
        elif (ip / "depth" / f"{key}.png").is_file():
            check_depth_png(ip / "depth" / f"{key}.png", key, DEPTH_SIZE)
            depth = ImageRef(path=ip / "depth" / f"{key}.png", kind="png")
        else:
            depth = None
        gt = ip / "gt_part_ids" / f"{key}.png"
        frames.append(Frame(
            frame_id=key, rgb=rgb, depth=depth, intrinsics=K,
            depth_intrinsics=K.scaled(*DEPTH_SIZE) if depth is not None else None,
            pose=pose, timestamp=entry.get("timestamp"),
            part_ids=ImageRef(path=gt, kind="png") if gt.is_file() else None,
        ))
    if depth_kind is None and all(f.depth is None for f in frames):
        notes.append("no depth found (iphone/depth.bin or iphone/depth/)")
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames),
                      source_format=NAME, gt_dir=find_gt_dir(root), notes=tuple(notes))


LAYOUT = Layout(NAME, "iphone/pose_intrinsic_imu.json", detect, load)
