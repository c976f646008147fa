"""Perception interfaces (model calls behind small protocols) and the weight-free backends."""

from ..stage import StageSpec
from .factory import make_perception
from .interfaces import (
    ArticulationPredictor,
    Perception,
    PointPromptSegmenter,
    Tagger,
    TagFilter,
    TextPromptSegmenter,
)
from .versions import HEURISTIC_VERSION, ORACLE_VERSION

STAGE_VERSION = "1"
STAGE = StageSpec("perception", __name__, STAGE_VERSION, sections=("perception",), upstream=("frames",),
                  parts={f"{__name__}.heuristic": HEURISTIC_VERSION, f"{__name__}.oracle": ORACLE_VERSION})

__all__ = [
    "STAGE",
    "STAGE_VERSION",
    "ArticulationPredictor",
    "Perception",
    "PointPromptSegmenter",
    "TagFilter",
    "Tagger",
    "TextPromptSegmenter",
    "make_perception",
]
