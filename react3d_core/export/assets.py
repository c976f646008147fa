"""Mesh files of an export, written once and shared by every format.

One asset folder per scene (``export/assets/<link>/``): textured visuals (OBJ+MTL+texture per
folder, optional GLB) and convex collision OBJs. URDF, MJCF and USD reference these files with
relative paths (``../assets/...`` from their own folders), so a 490k-face background is written
once instead of once per format, and the export can be moved as a whole. Visual vertices are in
link-local coordinates (world minus the link origin); a convex collision file is centred on its own
box centre (``ConvexPiece.centre``), which the URDF places with the collision's origin.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..config.export import ExportConfig
from ..texture import write_glb, write_obj_folder
from ..texture.writers import format_rows
from .model import SceneModel

ASSETS = "assets"
"""Name of the shared asset folder inside ``export/``."""


@dataclass
class LinkFiles:
    """Paths of one link's files, relative to the folder they were written under (see ``prefixed``)."""

    visuals: list[str] = field(default_factory=list)  # OBJ paths (each with its MTL/texture beside it)
    textures: list[str] = field(default_factory=list)  # texture paths, same order (the OBJ's own format)
    mjcf_textures: list[str] = field(default_factory=list)  # PNG paths, same order (MuJoCo reads PNG only)
    collisions: list[str] = field(default_factory=list)  # convex OBJ per piece
    patches: list[str] = field(default_factory=list)  # background convex patches that are not boxes, one OBJ each

    def prefixed(self, prefix: str) -> "LinkFiles":
        """The same files seen from another folder (``prefix`` = ``"../"`` from ``export/<format>/``)."""
        return LinkFiles(*([prefix + p for p in getattr(self, f)] for f in ("visuals", "textures", "mjcf_textures", "collisions", "patches")))


def write_plain_obj(path: Path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """Geometry-only OBJ (no MTL), vectorized formatting."""
    text = format_rows("v %.9g %.9g %.9g\n", np.asarray(vertices, float)) + format_rows("f %d %d %d\n", np.asarray(faces, np.int64) + 1)
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return path


def write_link_assets(model: SceneModel, folder: Path, config: ExportConfig | None = None, glb: bool | None = None,
                      collisions: bool = True, png_for_mjcf: bool = False, subdir: str = ASSETS) -> dict[str, LinkFiles]:
    """Write every link's meshes under ``folder/<subdir>/<link>/``; paths returned are relative to ``folder``.

    ``collisions``: also write the convex pieces and background patches as OBJ (URDF needs them;
    MJCF and USD inline them). ``png_for_mjcf``: a JPEG texture gets a PNG copy for MuJoCo.
    """
    config = config or ExportConfig()
    glb = config.write_glb if glb is None else glb
    out: dict[str, LinkFiles] = {}
    for link in model.links:
        d = folder / subdir / link.name
        files = LinkFiles()
        for k, tm in enumerate(link.visuals):
            obj = write_obj_folder(tm, d / f"visual_{k}", offset=link.frame, texture=config.texture_format,
                                   png_compression=config.png_compression, jpeg_quality=config.jpeg_quality,
                                   png_copy=png_for_mjcf)
            files.visuals.append(obj.relative_to(folder).as_posix())
            ext = "jpg" if config.texture_format == "jpg" else "png"
            files.textures.append((obj.parent / f"material_0.{ext}").relative_to(folder).as_posix())
            files.mjcf_textures.append((obj.parent / "material_0.png").relative_to(folder).as_posix())
            if glb:
                write_glb(tm, d / f"visual_{k}.glb", offset=link.frame)
        if collisions:
            for k, piece in enumerate(link.collisions):
                p = write_plain_obj(d / f"collision_{k}.obj", piece.vertices - piece.centre, piece.faces)
                files.collisions.append(p.relative_to(folder).as_posix())
            for k, piece in enumerate(link.patches):
                if piece.box is not None:
                    continue  # written as a box primitive
                p = write_plain_obj(d / "patches" / f"patch_{k}.obj", piece.vertices - piece.centre, piece.faces)
                files.patches.append(p.relative_to(folder).as_posix())
        out[link.name] = files
    return out
