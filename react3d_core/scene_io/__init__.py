"""Scene input: one module per input layout, the registry that detects and loads them (``layouts``),
frame selection, and the pixel readers behind ImageRefs."""

from ..stage import StageSpec
from .layouts import LAYOUTS, detect_layout, load_scene
from .selection import select_frames

STAGE_VERSION = "4"  # 4: returns of islands facing up or down fix no missed plane (frames.missed_surface.flat_island_nz)
STAGE = StageSpec("frames", __name__, STAGE_VERSION, sections=("frames",), upstream=())

__all__ = ["LAYOUTS", "STAGE", "detect_layout", "load_scene", "select_frames"]
