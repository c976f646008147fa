"""Scene input: loaders per layout, frame selection, and the pixel readers behind ImageRefs."""

from ..stage import StageSpec
from .loaders import detect_layout, load_scene
from .selection import select_frames

STAGE_VERSION = "1"
STAGE = StageSpec("frames", __name__, STAGE_VERSION, sections=("frames",), upstream=())

__all__ = ["STAGE", "detect_layout", "load_scene", "select_frames"]
