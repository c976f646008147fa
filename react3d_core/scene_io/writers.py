"""Write a :class:`SceneInput` in one of the layouts the loaders read, so every loader round-trips.

Poses and intrinsics go out in each layout's own convention (the inverse of the loader's conversion);
pixels are re-encoded from the ImageRefs (RGB as JPG/PNG, depth as depth.bin or uint16-mm PNG).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np

from ..atomic import atomic_path, write_json
from ..camera import K_SIZE, opencv_to_opengl_c2w
from ..data.frames import SceneInput
from . import iphone, nerfstudio, prepared
from .depth_bin import write_depth_bin
from .images import read_depth, read_rgb


def _write_image(path: Path, rgb: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        if not cv2.imwrite(str(tmp), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR) if rgb.ndim == 3 else rgb):
            raise OSError(f"cannot write {path}")


def _depth_png(path: Path, depth_m: np.ndarray) -> None:
    _write_image(path, np.clip(np.round(depth_m * 1000.0), 0, 65535).astype(np.uint16))


def _copy_mesh(scene: SceneInput, dst: Path) -> None:
    dst.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(dst) as tmp:
        shutil.copyfile(scene.mesh_path, tmp)


def _pose_json(scene: SceneInput) -> dict:
    return {f.frame_id: {"intrinsic": f.intrinsics.scaled(*K_SIZE).K.tolist(), "aligned_pose": f.c2w.tolist(),
                         "timestamp": f.timestamp} for f in scene.frames}


def write_scannetpp_iphone(scene: SceneInput, out: str | Path, depth_encoding: str = "per_frame") -> Path:
    """iphone/rgb/*.jpg, iphone/pose_intrinsic_imu.json (K for 1920x1440), iphone/depth.bin, scans/mesh."""
    out = Path(out)
    _copy_mesh(scene, out / "scans" / "mesh_aligned_0.05.ply")
    for f in scene.frames:
        _write_image(out / "iphone" / "rgb" / f"{f.frame_id}.jpg", read_rgb(f.rgb))
    if all(f.depth is not None for f in scene.frames):
        write_depth_bin(out / "iphone" / "depth.bin", [read_depth(f.depth, f.depth_scale) for f in scene.frames], depth_encoding)
    write_json(out / "iphone" / "pose_intrinsic_imu.json", _pose_json(scene))
    return out


def write_prepared(scene: SceneInput, out: str | Path) -> Path:
    """The reference code's layout: images_2/*.png, depth/*.png (uint16 mm), mesh, pose_intrinsic_imu.json."""
    out = Path(out)
    _copy_mesh(scene, out / "mesh_aligned_0.05.ply")
    for f in scene.frames:
        _write_image(out / "images_2" / f"{f.frame_id}.png", read_rgb(f.rgb))
        if f.depth is not None:
            _depth_png(out / "depth" / f"{f.frame_id}.png", read_depth(f.depth, f.depth_scale))
    write_json(out / "pose_intrinsic_imu.json", _pose_json(scene))
    return out


def write_generic(scene: SceneInput, out: str | Path) -> Path:
    """mesh.ply + nerfstudio transforms.json (c2w with OpenGL camera axes, shared intrinsics of frame 0)."""
    out = Path(out)
    _copy_mesh(scene, out / "mesh.ply")
    K = scene.frames[0].intrinsics
    frames = []
    for f in scene.frames:
        entry = {"file_path": f"images/{f.frame_id}.png", "transform_matrix": opencv_to_opengl_c2w(f.c2w).tolist()}
        _write_image(out / entry["file_path"], read_rgb(f.rgb))
        if f.depth is not None:
            entry["depth_file_path"] = f"depth/{f.frame_id}.png"
            _depth_png(out / entry["depth_file_path"], read_depth(f.depth, f.depth_scale))
        frames.append(entry)
    meta = {"fl_x": K.fx, "fl_y": K.fy, "cx": K.cx, "cy": K.cy, "w": K.width, "h": K.height, "frames": frames}
    write_json(out / "transforms.json", meta)
    return out


WRITERS = {iphone.NAME: write_scannetpp_iphone, prepared.NAME: write_prepared, nerfstudio.NAME: write_generic}
"""Writer per layout name (the ScanNet++ DSLR layout is read only: its fisheye images are not re-created)."""
