"""Scene input: one module per input layout, the registry that detects and loads them (``layouts``),
frame selection, and the pixel readers behind ImageRefs."""

from ..stage import StageSpec
from .layouts import LAYOUTS, detect_layout, load_scene
from .selection import select_frames

STAGE_VERSION = "3"  # 3: a missed plane whose returns are a layer of another's is dropped (frames.missed_surface.layer_*)
STAGE = StageSpec("frames", __name__, STAGE_VERSION, sections=("frames",), upstream=())

__all__ = ["LAYOUTS", "STAGE", "detect_layout", "load_scene", "select_frames"]
