"""Perception interfaces (model calls behind small protocols) and the weight-free backends."""

from .factory import make_perception
from .interfaces import (
    ArticulationPredictor,
    Perception,
    PointPromptSegmenter,
    Tagger,
    TagFilter,
    TextPromptSegmenter,
)

__all__ = [
    "ArticulationPredictor",
    "Perception",
    "PointPromptSegmenter",
    "TagFilter",
    "Tagger",
    "TextPromptSegmenter",
    "make_perception",
]
