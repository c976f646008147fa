"""Texture stage: UV atlases for scan meshes and vectorized baking of vertex colours into them.

``bake_texture(mesh, config)`` returns a :class:`TexturedMesh`; ``write_obj_folder`` / ``write_glb``
write it in the formats simulators read (see ``react3d_core.export``).
"""

from ..stage import StageSpec
from .atlas import ATLAS_FILL, cell_atlas, texture_side, xatlas_atlas
from .bake import TexturedMesh, bake_texture, fill_gutters, rasterize_uv, sample_bilinear, vertex_color_error
from .writers import write_glb, write_obj_folder

STAGE_VERSION = "2"  # 2: texture encoder options (png level, jpg)
STAGE = StageSpec("texture", __name__, STAGE_VERSION, sections=("export",), upstream=("assembly",))

__all__ = [
    "STAGE",
    "ATLAS_FILL",
    "STAGE_VERSION",
    "TexturedMesh",
    "bake_texture",
    "cell_atlas",
    "fill_gutters",
    "rasterize_uv",
    "sample_bilinear",
    "texture_side",
    "vertex_color_error",
    "write_glb",
    "write_obj_folder",
    "xatlas_atlas",
]
