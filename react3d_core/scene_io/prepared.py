"""The reference code's prepared layout: ``images_2/frame_XXXXXX.png`` (960x720), ``depth/*.png``
(uint16 mm, 256x192), ``mesh_aligned_0.05.ply`` and the ScanNet++ ``pose_intrinsic_imu.json`` beside them.
The images are a subset of the json's frames; only frames with an image are loaded."""

from __future__ import annotations

from pathlib import Path

from ..camera import K_SIZE
from ..data.frames import Frame, ImageRef, SceneInput
from ..errors import InputError
from .checks import DEPTH_SIZE, check_depth_png, checked_intrinsics, checked_mesh, checked_pose, read_json
from .images import image_size
from .layout import Layout, LoadOptions

NAME = "prepared"


def detect(root: Path) -> bool:
    return (root / "pose_intrinsic_imu.json").is_file() and (root / "images_2").is_dir()


def load(root: Path, options: LoadOptions) -> SceneInput:
    meta_path = root / "pose_intrinsic_imu.json"
    meta = read_json(meta_path)
    keys = sorted(k for k in meta if k.startswith("frame_"))
    mesh = checked_mesh(root / "mesh_aligned_0.05.ply")
    frames = []
    size = None
    for key in keys:
        p = root / "images_2" / f"{key}.png"
        if not p.is_file():
            continue  # the prepared layout keeps only a subset of the json frames
        size = size or image_size(p)
        entry = meta[key]
        K = checked_intrinsics(meta_path, key, entry["intrinsic"], *K_SIZE).scaled(*size)
        d = root / "depth" / f"{key}.png"
        if d.is_file():
            check_depth_png(d, key, DEPTH_SIZE)
        frames.append(Frame(frame_id=key, rgb=ImageRef(path=p, kind="png"),
                            depth=ImageRef(path=d, kind="png") if d.is_file() else None,
                            intrinsics=K, depth_intrinsics=K.scaled(*DEPTH_SIZE) if d.is_file() else None,
                            pose=checked_pose(meta_path, key, entry["aligned_pose"]), timestamp=entry.get("timestamp")))
    if not frames:
        raise InputError(root / "images_2", "no images matching pose_intrinsic_imu.json frames")
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames), source_format=NAME)


LAYOUT = Layout(NAME, "images_2/ + pose_intrinsic_imu.json", detect, load)
