"""ScanNet++ DSLR layout: COLMAP text model + fisheye images, undistorted and given mesh-rendered depth.

``dslr/colmap/{cameras,images}.txt`` (world-to-camera, qw qx qy qz; OPENCV_FISHEYE or PINHOLE),
``dslr/resized_images/`` (or ``resized_undistorted_images/``), mesh ``scans/mesh_aligned_0.05.ply``.
Follows the ScanNet++ toolkit: cv2.fisheye undistortion with balance 0, principal point forced to the
image centre, same size, poses unchanged; depth rendered from the mesh (near 0.05 m, far 20 m) because
the DSLR has none. Outputs go to a cache folder (default ``<scene>/.react3d_cache``; inputs are never
modified) and are reused if present; frames are selected first, so unselected frames cost nothing.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ..atomic import atomic_path
from ..camera import colmap_to_c2w
from ..data.frames import Frame, ImageRef, Intrinsics, SceneInput
from ..data.mesh import load_mesh
from ..errors import InputError
from .checks import checked_mesh, find_gt_dir
from .layout import Layout, LoadOptions

NAME = "scannetpp_dslr"

NEAR, FAR = 0.05, 20.0


def read_colmap_camera(path: Path) -> tuple[int, int, np.ndarray, np.ndarray]:
    """First camera of cameras.txt: (width, height, K, D[k1..k4]); OPENCV_FISHEYE or PINHOLE."""
    if not path.is_file():
        raise InputError(path, "file not found")
    for line in path.read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        t = line.split()
        model, w, h, p = t[1], int(t[2]), int(t[3]), [float(x) for x in t[4:]]
        if model == "OPENCV_FISHEYE" and len(p) == 8:
            D = np.array(p[4:8])
        elif model == "PINHOLE" and len(p) == 4:
            D = np.zeros(4)
        else:
            raise InputError(path, f"unsupported camera model {model} with {len(p)} parameters")
        K = np.array([[p[0], 0, p[2]], [0, p[1], p[3]], [0, 0, 1.0]])
        if p[0] <= 0 or p[1] <= 0:
            raise InputError(path, f"non-positive focal length fx={p[0]} fy={p[1]}")
        return w, h, K, D
    raise InputError(path, "no camera line")


def read_colmap_images(path: Path) -> list[tuple[str, np.ndarray]]:
    """(image name, c2w OpenCV) from images.txt (world-to-camera quaternion lines; every 2nd line is points)."""
    if not path.is_file():
        raise InputError(path, "file not found")
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    out = []
    for ln in lines[0::2]:
        t = ln.split()
        if len(t) < 10:
            continue
        vals = np.array([float(x) for x in t[1:8]])
        if not np.all(np.isfinite(vals)):
            raise InputError(path, f"image {t[9]}: pose contains NaN or inf")
        out.append((t[9], colmap_to_c2w(vals[:4], vals[4:7])))
    if not out:
        raise InputError(path, "no images")
    return sorted(out)


def undistorted_intrinsics(K: np.ndarray, D: np.ndarray, w: int, h: int) -> np.ndarray:
    """Toolkit's new K: balance 0, principal point at the image centre."""
    newK = cv2.fisheye.estimateNewCameraMatrixForUndistortRectify(K, D, (w, h), np.eye(3), balance=0.0)
    newK[0, 2], newK[1, 2] = w / 2.0, h / 2.0
    return newK


def load_dslr_frames(root: Path, cache: Path, mesh_path: Path, select) -> list[Frame]:  # noqa: ANN001
    """Frames with undistorted RGB and rendered depth (uint16 mm PNG) written into ``cache`` for the
    frames ``select`` keeps (selection first, so unused frames cost nothing)."""
    colmap = root / "dslr" / "colmap"
    w, h, K, D = read_colmap_camera(colmap / "cameras.txt")
    newK = undistorted_intrinsics(K, D, w, h)
    img_dir = next((d for d in (root / "dslr" / "resized_undistorted_images", root / "dslr" / "resized_images") if d.is_dir()), None)
    if img_dir is None:
        raise InputError(root / "dslr" / "resized_images", "DSLR image folder not found")
    already = img_dir.name == "resized_undistorted_images"
    intr = Intrinsics.from_K(newK if not already else K, w, h)
    frames, sources = [], {}
    for name, c2w in read_colmap_images(colmap / "images.txt"):
        stem = Path(name).stem
        src = img_dir / name
        if not src.is_file():
            raise InputError(src, "image file not found")
        sources[stem] = src
        rgb = src if already else cache / "rgb" / f"{stem}.png"
        frames.append(Frame(frame_id=stem, rgb=ImageRef(path=rgb, kind="png" if rgb.suffix == ".png" else "jpg"),
                            depth=ImageRef(path=cache / "depth" / f"{stem}.png", kind="png"),
                            intrinsics=intr, depth_intrinsics=intr, pose=c2w))
    frames = select(frames)
    from ..raster.rasterizer import Rasterizer

    raster = None
    m1 = m2 = None
    for f in frames:
        if not already and not f.rgb.path.is_file():
            if m1 is None:
                m1, m2 = cv2.fisheye.initUndistortRectifyMap(K, D, np.eye(3), newK, (w, h), cv2.CV_16SC2)
            img = cv2.imread(str(sources[f.frame_id]), cv2.IMREAD_COLOR)
            if img is None:
                raise InputError(sources[f.frame_id], "cannot decode image")
            _write(f.rgb.path, cv2.remap(img, m1, m2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT))
        if not f.depth.path.is_file():
            if raster is None:
                mesh = load_mesh(mesh_path)
                if mesh.n_faces == 0:
                    raise InputError(mesh_path, "mesh has no faces")
                raster = Rasterizer(mesh)
            d = raster.render(intr.K, f.c2w, w, h, f.frame_id).depth
            d[(d < NEAR) | (d > FAR)] = 0
            _write(f.depth.path, np.round(d * 1000.0).astype(np.uint16))
    return frames


def _write(path: Path, img: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        if not cv2.imwrite(str(tmp), img):
            raise OSError(f"cannot write {path}")


def detect(root: Path) -> bool:
    return (root / "dslr" / "colmap" / "images.txt").is_file()


def load(root: Path, options: LoadOptions) -> SceneInput:
    mesh = checked_mesh(root / "scans" / "mesh_aligned_0.05.ply")
    cache = Path(options.cache_dir) if options.cache_dir else root / ".react3d_cache"
    frames = load_dslr_frames(root, cache / "dslr", mesh, lambda fs: options.select(list(fs), mesh))
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames), source_format=NAME,
                      gt_dir=find_gt_dir(root))


LAYOUT = Layout(NAME, "dslr/colmap/images.txt", detect, load, selects_frames=True)
