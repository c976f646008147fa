"""Load a scan folder into a :class:`SceneInput`, auto-detecting its layout.

Supported here: the ScanNet++ iPhone layout (what the synthetic writer produces), the reference
code's prepared layout (images_2/ + depth/ PNG), and a generic mesh + nerfstudio transforms.json.
Conventions are converted at this boundary: every pose leaves as camera-to-world with OpenCV axes.
and the ScanNet++ DSLR layout (dslr.py: fisheye undistortion + mesh-rendered depth into a cache folder).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import cv2
from PIL import Image as PILImage
import numpy as np

from ..camera import K_SIZE, nerfstudio_scannetpp_to_c2w, opengl_to_opencv_c2w
from ..config.scene_io import FrameSelectionConfig
from ..data.frames import Frame, ImageRef, Intrinsics, SceneInput, validate_pose
from ..errors import InputError
from ..raster import Rasterizer
from .depth_bin import DepthBin
from .images import check_jpeg_complete, depth_size_problem
from .selection import FrameSelection, SelectionMemo, choose_frames_memo

DEPTH_SIZE = (256, 192)


def _image_size(path: Path) -> tuple[int, int]:
    """(width, height) of an image file or of the first frame of a video. PNG and JPEG sizes come from
    their headers (a scan's check ran 250 full decodes of depth PNGs before Prefect even started)."""
    suffix = path.suffix.lower()
    if suffix == ".png" and (size := _png_size(path)) is not None:
        return size
    if suffix in (".jpg", ".jpeg"):
        check_jpeg_complete(path)
        try:
            with PILImage.open(path) as im:
                return int(im.size[0]), int(im.size[1])
        except (OSError, SyntaxError):
            raise InputError(path, "cannot decode image") from None
    if path.suffix.lower() in (".mkv", ".mp4"):
        cap = cv2.VideoCapture(str(path))
        ok, img = cap.read()
        cap.release()
    else:
        img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        ok = img is not None
    if not ok:
        raise InputError(path, "cannot decode image")
    return int(img.shape[1]), int(img.shape[0])


def _png_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from a PNG's IHDR chunk (24 bytes read), None when it is not a PNG."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def _check_depth_png(path: Path, frame_id: str, size: tuple[int, int]) -> None:
    """Per frame, at load: a depth PNG must have the size the layout declares (256x192 for ScanNet++)."""
    got = _png_size(path)
    if got is None:
        raise InputError(path, f"{frame_id}: not a PNG depth image")
    if got != size:
        raise InputError(path, depth_size_problem(frame_id, *got, *size))


def _read_json(path: Path) -> dict:
    if not path.is_file():
        raise InputError(path, "file not found")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise InputError(path, f"invalid JSON ({e.msg if hasattr(e, 'msg') else e})") from None


def _msg(e: Exception) -> str:
    """First message of a pydantic ValidationError (one line), else str(e)."""
    errs = getattr(e, "errors", None)
    if callable(errs):
        try:
            return str(errs()[0]["msg"]).removeprefix("Value error, ")
        except (IndexError, KeyError, TypeError):
            pass
    return str(e).splitlines()[0] if str(e) else type(e).__name__


def _check_pose(path: Path, key: str, pose: object) -> np.ndarray:
    try:
        return validate_pose(np.asarray(pose, dtype=float))
    except (ValueError, TypeError) as e:
        raise InputError(path, f"{key}: {e}") from None


def _intrinsics(path: Path, key: str, K: object, width: int, height: int) -> Intrinsics:
    try:
        return Intrinsics.from_K(np.asarray(K, dtype=float).reshape(3, 3), width, height)
    except (ValueError, TypeError) as e:
        raise InputError(path, f"{key}: intrinsics invalid: {_msg(e)}") from None


def _check_mesh(path: Path) -> Path:
    if not path.is_file():
        raise InputError(path, "mesh file not found")
    if path.stat().st_size == 0:
        raise InputError(path, "mesh file is empty")
    if path.suffix.lower() == ".ply":
        _check_ply_header(path)
    return path


def _check_ply_header(path: Path) -> None:
    """Cheap corrupt/empty check from the PLY header alone (the full mesh is loaded only by the stages)."""
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if not head.startswith(b"ply"):
        raise InputError(path, "corrupt mesh: not a PLY file (missing 'ply' magic)")
    if b"end_header" not in head:
        raise InputError(path, "corrupt mesh: PLY header not terminated")
    counts = {}
    for line in head.split(b"end_header")[0].decode("ascii", "replace").splitlines():
        t = line.split()
        if len(t) == 3 and t[0] == "element" and t[2].isdigit():
            counts[t[1]] = int(t[2])
    if counts.get("vertex", 0) == 0 or counts.get("face", 0) == 0:
        raise InputError(path, f"empty mesh: {counts.get('vertex', 0)} vertices, {counts.get('face', 0)} faces")


def detect_layout(root: Path) -> str:
    """Which layout ``root`` holds: 'scannetpp_iphone', 'prepared' or 'generic'."""
    if (root / "iphone" / "pose_intrinsic_imu.json").is_file():
        return "scannetpp_iphone"
    if (root / "pose_intrinsic_imu.json").is_file() and (root / "images_2").is_dir():
        return "prepared"
    if (root / "transforms.json").is_file():
        return "generic"
    if (root / "dslr" / "colmap" / "images.txt").is_file():
        return "scannetpp_dslr"
    raise InputError(root, "no known scene layout (expected iphone/pose_intrinsic_imu.json, images_2/ + pose_intrinsic_imu.json, or transforms.json)")


def _load_iphone(root: Path) -> SceneInput:
    ip = root / "iphone"
    meta_path = ip / "pose_intrinsic_imu.json"
    meta = _read_json(meta_path)
    keys = sorted(k for k in meta if k.startswith("frame_"))
    if not keys:
        raise InputError(meta_path, "no frame_XXXXXX entries")
    mesh = _check_mesh(root / "scans" / "mesh_aligned_0.05.ply")
    mkv = ip / "rgb.mkv"
    use_mkv = not (ip / "rgb").is_dir() and mkv.is_file()
    if not use_mkv and not (ip / "rgb").is_dir():
        raise InputError(ip / "rgb", "RGB folder (or rgb.mkv) not found")
    first = mkv if use_mkv else ip / "rgb" / f"{keys[0]}.jpg"
    if not first.is_file():
        raise InputError(first, "image file not found")
    w, h = _image_size(first)
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
        K = _intrinsics(meta_path, key, entry["intrinsic"], *K_SIZE).scaled(w, h)
        pose = _check_pose(meta_path, key, entry["aligned_pose"])
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
            _check_depth_png(ip / "depth" / f"{key}.png", key, DEPTH_SIZE)
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
    gt_dir = next((d for d in (root / "articulate3d", root.parent / "articulate3d") if d.is_dir()), None)
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames),
                      source_format="scannetpp_iphone", gt_dir=gt_dir, notes=tuple(notes))


def _load_prepared(root: Path) -> SceneInput:
    meta_path = root / "pose_intrinsic_imu.json"
    meta = _read_json(meta_path)
    keys = sorted(k for k in meta if k.startswith("frame_"))
    mesh = _check_mesh(root / "mesh_aligned_0.05.ply")
    frames = []
    size = None
    for key in keys:
        p = root / "images_2" / f"{key}.png"
        if not p.is_file():
            continue  # the prepared layout keeps only a subset of the json frames
        size = size or _image_size(p)
        entry = meta[key]
        K = _intrinsics(meta_path, key, entry["intrinsic"], *K_SIZE).scaled(*size)
        d = root / "depth" / f"{key}.png"
        if d.is_file():
            _check_depth_png(d, key, DEPTH_SIZE)
        frames.append(Frame(frame_id=key, rgb=ImageRef(path=p, kind="png"),
                            depth=ImageRef(path=d, kind="png") if d.is_file() else None,
                            intrinsics=K, depth_intrinsics=K.scaled(*DEPTH_SIZE) if d.is_file() else None,
                            pose=_check_pose(meta_path, key, entry["aligned_pose"]), timestamp=entry.get("timestamp")))
    if not frames:
        raise InputError(root / "images_2", "no images matching pose_intrinsic_imu.json frames")
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames), source_format="prepared")


def _load_generic(root: Path, scannetpp_world: bool | None = None) -> SceneInput:
    """Mesh + nerfstudio transforms.json. Plain nerfstudio poses are c2w with OpenGL camera axes;
    a ScanNet++ nerfstudio file (auto-detected when the file sits under ``dslr/`` or the flag is set)
    additionally has the permuted world, undone with :func:`nerfstudio_scannetpp_to_c2w`."""
    tp = root / "transforms.json"
    meta = _read_json(tp)
    if scannetpp_world is None:
        scannetpp_world = root.name == "nerfstudio" and root.parent.name == "dslr"
    meshes = sorted(root.glob("*.ply")) + sorted(root.glob("*.obj"))
    mesh_path = Path(meta["mesh_path"]) if "mesh_path" in meta else (meshes[0] if meshes else root / "mesh.ply")
    mesh = _check_mesh(mesh_path if mesh_path.is_absolute() else root / mesh_path)
    try:
        base = Intrinsics(fx=meta["fl_x"], fy=meta["fl_y"], cx=meta["cx"], cy=meta["cy"], width=int(meta["w"]), height=int(meta["h"]))
    except KeyError as e:
        raise InputError(tp, f"missing key {e}") from None
    except ValueError as e:
        raise InputError(tp, f"intrinsics invalid: {_msg(e)}") from None
    frames = []
    for i, fr in enumerate(meta.get("frames", [])):
        T = _check_pose(tp, f"frames[{i}]", fr["transform_matrix"])
        c2w = nerfstudio_scannetpp_to_c2w(T) if scannetpp_world else opengl_to_opencv_c2w(T)
        p = root / fr["file_path"]
        if not p.is_file():
            raise InputError(p, "image file not found")
        dref, dK = None, None
        if fr.get("depth_file_path"):
            dp = root / fr["depth_file_path"]
            if not dp.is_file():
                raise InputError(dp, "depth file not found")
            dref = ImageRef(path=dp, kind="npy" if dp.suffix == ".npy" else "png")
            dK = base.scaled(*_image_size(dp)) if dp.suffix != ".npy" else base
        kind = "png" if p.suffix.lower() == ".png" else "jpg"
        if p.suffix.lower() in (".jpg", ".jpeg"):
            check_jpeg_complete(p)
        frames.append(Frame(frame_id=p.stem, rgb=ImageRef(path=p, kind=kind), depth=dref, intrinsics=base,
                            depth_intrinsics=dK, pose=c2w))
    if not frames:
        raise InputError(tp, "no frames")
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames), source_format="generic")


def load_scene(path: str | Path, selection: FrameSelectionConfig | None = None, *,
               layout: str | None = None, scannetpp_world: bool | None = None,
               cache_dir: str | Path | None = None, rasterizer: Callable[[Path], Rasterizer] | None = None,
               memo: SelectionMemo | None = None) -> SceneInput:
    """Load any supported layout (auto-detected unless ``layout`` is given), then select frames.

    ``cache_dir`` (DSLR only; default ``<scene>/.react3d_cache``) receives undistorted images and rendered depth.
    ``rasterizer(mesh_path)`` gives the scan's :class:`~react3d_core.raster.Rasterizer` for the coverage rule
    of keyframe selection (default: built from the mesh here; callers that keep one pass theirs);
    ``memo`` remembers keyframe selections by content, so a re-run does not render the frames again."""
    root = Path(path)
    if not root.is_dir():
        raise InputError(root, "scene folder not found")
    layout = layout or detect_layout(root)
    chosen: list[FrameSelection] = []

    def sel(frames: list[Frame], mesh: Path) -> list[Frame]:
        if selection is None:
            return frames
        def raster() -> Rasterizer:
            return rasterizer(mesh) if rasterizer is not None else _default_rasterizer(mesh)

        chosen.append(choose_frames_memo(frames, selection, mesh, raster, memo))
        return chosen[-1].frames

    if layout == "scannetpp_dslr":
        from .dslr import load_dslr_frames

        mesh = _check_mesh(root / "scans" / "mesh_aligned_0.05.ply")
        cache = Path(cache_dir) if cache_dir else root / ".react3d_cache"
        frames = load_dslr_frames(root, cache / "dslr", mesh, lambda fs: sel(list(fs), mesh))
        gt_dir = next((d for d in (root / "articulate3d", root.parent / "articulate3d") if d.is_dir()), None)
        return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames),
                          source_format="scannetpp_dslr", gt_dir=gt_dir,
                          frame_selection=chosen[-1].reason if chosen else "")
    if layout == "scannetpp_iphone":
        scene = _load_iphone(root)
    elif layout == "prepared":
        scene = _load_prepared(root)
    elif layout == "generic":
        scene = _load_generic(root, scannetpp_world)
    else:
        raise InputError(root, f"unsupported layout {layout!r}")
    if selection is not None:
        frames = sel(list(scene.frames), scene.mesh_path)
        scene = scene.model_copy(update={"frames": tuple(frames), "frame_selection": chosen[-1].reason})
    return scene


def _default_rasterizer(mesh_path: Path) -> Rasterizer:
    from ..data.mesh import load_mesh

    return Rasterizer(load_mesh(mesh_path))
