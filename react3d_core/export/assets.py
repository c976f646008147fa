"""Mesh files of an export: textured visuals (OBJ+MTL+PNG per folder, GLB) and convex collision OBJs.

Vertices are written in link-local coordinates (world minus the link origin). Paths returned are
relative to the format's folder, so the export can be moved as a whole.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..texture import write_glb, write_obj_folder
from ..texture.writers import format_rows
from .model import SceneModel


@dataclass
class LinkFiles:
    visuals: list[str] = field(default_factory=list)  # OBJ paths (each with its MTL/PNG beside it)
    textures: list[str] = field(default_factory=list)  # PNG paths, same order
    collisions: list[str] = field(default_factory=list)  # convex OBJ per piece
    patches: list[str] = field(default_factory=list)  # background convex patches, one OBJ each


def write_plain_obj(path: Path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """Geometry-only OBJ (no MTL), vectorized formatting."""
    text = format_rows("v %.9g %.9g %.9g\n", np.asarray(vertices, float)) + format_rows("f %d %d %d\n", np.asarray(faces, np.int64) + 1)
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return path


def write_link_assets(model: SceneModel, folder: Path, glb: bool = True, collisions: bool = True) -> dict[str, LinkFiles]:
    """Write every link's meshes under ``folder/meshes/<link>/``."""
    out: dict[str, LinkFiles] = {}
    for link in model.links:
        d = folder / "meshes" / link.name
        files = LinkFiles()
        for k, tm in enumerate(link.visuals):
            obj = write_obj_folder(tm, d / f"visual_{k}", offset=link.frame)
            files.visuals.append(obj.relative_to(folder).as_posix())
            files.textures.append((obj.parent / "material_0.png").relative_to(folder).as_posix())
            if glb:
                write_glb(tm, d / f"visual_{k}.glb", offset=link.frame)
        if collisions:
            for k, piece in enumerate(link.collisions):
                p = write_plain_obj(d / f"collision_{k}.obj", piece.vertices - link.frame, piece.faces)
                files.collisions.append(p.relative_to(folder).as_posix())
            for k, piece in enumerate(link.patches):
                p = write_plain_obj(d / "patches" / f"patch_{k}.obj", piece.vertices - link.frame, piece.faces)
                files.patches.append(p.relative_to(folder).as_posix())
        out[link.name] = files
    return out
