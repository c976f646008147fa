"""The generic layout: a mesh plus a nerfstudio-style ``transforms.json``.

Shared intrinsics ``fl_x, fl_y, cx, cy, w, h``; per frame ``file_path``, ``transform_matrix`` and an
optional ``depth_file_path`` (uint16-mm PNG or float-metres .npy). Plain nerfstudio poses are
camera-to-world with OpenGL camera axes; a ScanNet++ nerfstudio file (auto-detected when the file sits
in ``dslr/nerfstudio/``, or ``scannetpp_world`` set) additionally has a permuted world, undone with
:func:`~react3d_core.camera.nerfstudio_scannetpp_to_c2w`. The mesh is ``mesh_path`` from the json, else
the first ``*.ply`` / ``*.obj`` in the folder.
"""

from __future__ import annotations

from pathlib import Path

from ..camera import nerfstudio_scannetpp_to_c2w, opengl_to_opencv_c2w
from ..data.frames import Frame, ImageRef, Intrinsics, SceneInput
from ..errors import InputError
from .checks import checked_mesh, checked_pose, first_message, read_json
from .images import check_jpeg_complete, image_size
from .layout import Layout, LoadOptions

NAME = "generic"


def detect(root: Path) -> bool:
    return (root / "transforms.json").is_file()


def load(root: Path, options: LoadOptions) -> SceneInput:
    tp = root / "transforms.json"
    meta = read_json(tp)
    scannetpp_world = options.scannetpp_world
    if scannetpp_world is None:
        scannetpp_world = root.name == "nerfstudio" and root.parent.name == "dslr"
    meshes = sorted(root.glob("*.ply")) + sorted(root.glob("*.obj"))
    mesh_path = Path(meta["mesh_path"]) if "mesh_path" in meta else (meshes[0] if meshes else root / "mesh.ply")
    mesh = checked_mesh(mesh_path if mesh_path.is_absolute() else root / mesh_path)
    try:
        base = Intrinsics(fx=meta["fl_x"], fy=meta["fl_y"], cx=meta["cx"], cy=meta["cy"], width=int(meta["w"]), height=int(meta["h"]))
    except KeyError as e:
        raise InputError(tp, f"missing key {e}") from None
    except ValueError as e:
        raise InputError(tp, f"intrinsics invalid: {first_message(e)}") from None
    frames = []
    for i, fr in enumerate(meta.get("frames", [])):
        T = checked_pose(tp, f"frames[{i}]", fr["transform_matrix"])
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
            dK = base.scaled(*image_size(dp)) if dp.suffix != ".npy" else base
        kind = "png" if p.suffix.lower() == ".png" else "jpg"
        if p.suffix.lower() in (".jpg", ".jpeg"):
            check_jpeg_complete(p)
        frames.append(Frame(frame_id=p.stem, rgb=ImageRef(path=p, kind=kind), depth=dref, intrinsics=base,
                            depth_intrinsics=dK, pose=c2w))
    if not frames:
        raise InputError(tp, "no frames")
    return SceneInput(scene_id=root.name, root=root, mesh_path=mesh, frames=tuple(frames), source_format=NAME)


LAYOUT = Layout(NAME, "transforms.json", detect, load)
