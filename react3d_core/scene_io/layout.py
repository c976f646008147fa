"""What an input layout module declares: how to recognise a scan folder in that layout and how to load it.

Every layout module (``iphone``, ``prepared``, ``nerfstudio``, ``dslr``) ends with one :class:`Layout`;
``layouts.LAYOUTS`` lists them in detection order and is the only place that dispatches on layout.
A layout converts its own conventions at this boundary: every pose leaves as camera-to-world with
OpenCV axes, every K belongs to the image it is paired with.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..data.frames import Frame, SceneInput

FrameSelector = Callable[[Sequence[Frame], Path], list[Frame]]
"""``select(frames, mesh_path)``: the frames to keep (all of them when no selection was asked)."""


@dataclass(frozen=True)
class LoadOptions:
    """What ``load_scene`` hands every layout's loader; each reads only what applies to it."""

    select: FrameSelector
    cache_dir: Path | None = None
    """Where a layout that derives files (DSLR: undistorted images, rendered depth) writes them."""
    scannetpp_world: bool | None = None
    """nerfstudio poses in ScanNet++'s permuted world (None: decide from where the file sits)."""


@dataclass(frozen=True)
class Layout:
    """One input layout: its name (the scene's ``source_format``), how to recognise it, how to load it."""

    name: str
    looks_for: str
    """What ``detect`` checks, in words, for the error on a folder no layout recognises."""
    detect: Callable[[Path], bool]
    load: Callable[[Path, LoadOptions], SceneInput]
    selects_frames: bool = False
    """``load`` applies ``options.select`` itself, before its per-frame work (DSLR undistorts and
    renders only the kept frames); otherwise ``load_scene`` selects from the loaded frames."""
