"""Write textured meshes: OBJ + MTL + PNG (one folder per link: trimesh uses fixed names) and GLB."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from .bake import TexturedMesh


def _trimesh(tm: TexturedMesh, offset: np.ndarray | None = None):  # noqa: ANN202
    import trimesh
    from PIL import Image

    v = tm.vertices if offset is None else tm.vertices - np.asarray(offset, float)
    material = trimesh.visual.material.SimpleMaterial(image=Image.fromarray(tm.image), diffuse=(255, 255, 255, 255))
    visual = trimesh.visual.TextureVisuals(uv=tm.uv, material=material)
    return trimesh.Trimesh(v, tm.faces, visual=visual, process=False)


def write_obj_folder(tm: TexturedMesh, folder: str | Path, offset: np.ndarray | None = None) -> Path:
    """Write ``folder/mesh.obj`` with ``material.mtl`` and ``material_0.png``; vertices minus ``offset``.

    The folder is written whole (temp + rename) because trimesh names the MTL/PNG itself.
    """
    from ..atomic import atomic_dir

    folder = Path(folder)
    with atomic_dir(folder) as tmp:
        _trimesh(tm, offset).export(tmp / "mesh.obj", include_normals=False)
    return folder / "mesh.obj"


def write_glb(tm: TexturedMesh, path: str | Path, offset: np.ndarray | None = None) -> Path:
    """Write a binary glTF with the texture embedded."""
    path = Path(path)
    with atomic_path(path) as tmp:
        _trimesh(tm, offset).export(tmp, file_type="glb")
    return path
