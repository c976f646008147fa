"""The five model calls of the paper as small typed protocols.

Backends (DESIGN.md): ``heuristic`` (weight-free, RGB-D only, in react3d_core.perception.heuristic),
``oracle`` (ground truth + configurable noise, react3d_core.perception.oracle) and ``models``
(foundation models, react3d_models/ — the only code that loads weights). Every call takes a batch of
frames so GPU backends can batch; images are passed as arrays at the frame's RGB resolution.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from ..data.frames import Frame
from ..data.masks import ArticulationPrediction, Mask2D


@runtime_checkable
class Tagger(Protocol):
    """Image tagging (RAM++ in the paper): a set of tags per frame."""

    def tag(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[str]]: ...


@runtime_checkable
class TagFilter(Protocol):
    """Keeps the tags that have a revolute/prismatic moving part (LLaVA in the paper); always keeps 'door'."""

    def filter(self, tags: Sequence[str]) -> list[str]: ...


@runtime_checkable
class TextPromptSegmenter(Protocol):
    """Open-vocabulary detection + SAM box prompts (Grounded-SAM): masks of openable parts per frame."""

    def segment(
        self, frames: Sequence[Frame], images: Sequence[np.ndarray], phrases: Sequence[str]
    ) -> list[list[Mask2D]]: ...


@runtime_checkable
class PointPromptSegmenter(Protocol):
    """SAM with point prompts: one mask per (frame, prompt set). ``points`` (N,2) px, ``labels`` 1/0."""

    def segment_points(
        self, frame: Frame, image: np.ndarray, points: np.ndarray, labels: np.ndarray
    ) -> Mask2D: ...


@runtime_checkable
class ArticulationPredictor(Protocol):
    """OPDMulti: per-view part masks with joint type, axis and origin in the camera frame."""

    def predict(self, frames: Sequence[Frame], images: Sequence[np.ndarray]) -> list[list[ArticulationPrediction]]: ...


@dataclass
class Perception:
    """A complete backend: the five calls, plus its name for manifests and cache keys."""

    name: str
    tagger: Tagger
    tag_filter: TagFilter
    segmenter: TextPromptSegmenter
    point_segmenter: PointPromptSegmenter
    articulation: ArticulationPredictor
    version: str = "0"
