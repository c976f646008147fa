"""Scene input: loaders per layout, frame selection, and the pixel readers behind ImageRefs."""

from .loaders import detect_layout, load_scene
from .selection import select_frames

__all__ = ["detect_layout", "load_scene", "select_frames"]
