"""Write textured meshes: OBJ + MTL + PNG (one folder per link: trimesh uses fixed names) and GLB."""

from __future__ import annotations

from pathlib import Path
from typing import Any

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


def format_rows(fmt: str, rows: np.ndarray) -> str:
    """``fmt`` applied to every row in one C-level ``%`` call (no per-row Python loop)."""
    rows = np.asarray(rows)
    if not len(rows):
        return ""
    return (fmt * len(rows)) % tuple(rows.ravel().tolist())


ROWS_PER_CHUNK = 250_000
"""Rows formatted per ``%`` call: bounds the temporary tuple and string (a 1.25M-face background's
3.75M ``vt`` rows at once held ~0.5 GB of Python floats) at no measurable speed cost."""


def write_rows(fh: Any, fmt: str, rows: np.ndarray) -> None:
    """``format_rows`` in chunks of :data:`ROWS_PER_CHUNK`, written to the open text file ``fh``."""
    rows = np.asarray(rows)
    for i in range(0, len(rows), ROWS_PER_CHUNK):
        fh.write(format_rows(fmt, rows[i : i + ROWS_PER_CHUNK]))


def encode_texture(image: np.ndarray, fmt: str = "png", png_compression: int = 3, jpeg_quality: int = 90) -> bytes:
    """RGB uint8 image -> PNG or JPEG bytes (OpenCV's encoders: the fastest here, ~0.5 s for 2430^2 PNG)."""
    import cv2

    bgr = np.ascontiguousarray(np.asarray(image)[..., ::-1])
    if fmt == "png":
        ok, buf = cv2.imencode(".png", bgr, [cv2.IMWRITE_PNG_COMPRESSION, int(png_compression)])
    elif fmt in ("jpg", "jpeg"):
        ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, int(jpeg_quality)])
    else:
        raise ValueError(f"unknown texture format {fmt!r} (png, jpg)")
    if not ok:
        raise OSError(f"cannot encode a {image.shape} texture as {fmt}")
    return buf.tobytes()


def write_obj_folder(tm: TexturedMesh, folder: str | Path, offset: np.ndarray | None = None, texture: str = "png",
                     png_compression: int = 3, jpeg_quality: int = 90, png_copy: bool = False) -> Path:
    """Write ``folder/mesh.obj`` + ``material.mtl`` + ``material_0.<png|jpg>`` (trimesh's names), atomically.

    Positions are written once per scan vertex and UVs once per atlas vertex (``f v/vt``), so the
    per-triangle atlas of a large scan does not triple the positions. Vertices are minus ``offset``.
    ``png_copy`` adds ``material_0.png`` beside a JPEG texture (MuJoCo reads PNG only).
    """
    from ..atomic import atomic_dir

    folder = Path(folder)
    _, first, inv = np.unique(tm.source_vertex, return_index=True, return_inverse=True)
    v = tm.vertices[first] - (0.0 if offset is None else np.asarray(offset, float))
    fv = inv.reshape(-1)[tm.faces] + 1
    ft = np.asarray(tm.faces, np.int64) + 1
    corners = np.stack([fv, ft], -1).reshape(len(tm.faces), 6)
    with atomic_dir(folder) as tmp:
        with open(tmp / "mesh.obj", "w") as fh:
            fh.write("# REACT3D baked mesh\nmtllib material.mtl\nusemtl material_0\n")
            write_rows(fh, "v %.7g %.7g %.7g\n", v)
            # fixed 5 decimals: <= 5e-6 in UV, 0.02 texel on a 4096 texture; ~20 % smaller than %.7g
            # on the cell atlas, whose small u values (0.0001459854) spent digits on leading zeros
            write_rows(fh, "vt %.5f %.5f\n", tm.uv)
            write_rows(fh, "f %d/%d %d/%d %d/%d\n", corners)
        ext = "jpg" if texture in ("jpg", "jpeg") else "png"
        (tmp / "material.mtl").write_text(
            f"newmtl material_0\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\nmap_Kd material_0.{ext}\n"
        )
        (tmp / f"material_0.{ext}").write_bytes(encode_texture(tm.image, ext, png_compression, jpeg_quality))
        if png_copy and ext != "png":
            (tmp / "material_0.png").write_bytes(encode_texture(tm.image, "png", png_compression))
    return folder / "mesh.obj"


def write_glb(tm: TexturedMesh, path: str | Path, offset: np.ndarray | None = None) -> Path:
    """Write a binary glTF with the texture embedded."""
    path = Path(path)
    with atomic_path(path) as tmp:
        _trimesh(tm, offset).export(tmp, file_type="glb")
    return path
