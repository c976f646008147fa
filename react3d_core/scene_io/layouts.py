"""Load a scan folder into a :class:`SceneInput`: find its layout in the registry, load it, select frames.

``LAYOUTS`` is the registry, in detection order (the first layout whose ``detect`` accepts the folder
wins: a ScanNet++ scene holding both ``iphone/`` and ``dslr/`` loads as iPhone). Each layout module
(:mod:`.iphone`, :mod:`.prepared`, :mod:`.nerfstudio`, :mod:`.dslr`) declares how it is recognised and
loaded; nothing here knows one layout from another, so a new layout is one module and one entry below.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from ..config.scene_io import FrameSelectionConfig
from ..data.frames import Frame, SceneInput
from ..errors import InputError
from ..raster import Rasterizer
from . import dslr, iphone, nerfstudio, prepared
from .layout import Layout, LoadOptions
from .selection import FrameSelection, SelectionMemo, choose_frames_memo

LAYOUTS: tuple[Layout, ...] = (iphone.LAYOUT, prepared.LAYOUT, nerfstudio.LAYOUT, dslr.LAYOUT)


def layout_named(name: str, root: Path | None = None) -> Layout:
    for layout in LAYOUTS:
        if layout.name == name:
            return layout
    raise InputError(root, f"unsupported layout {name!r} (known: {', '.join(lay.name for lay in LAYOUTS)})")


def detect_layout(root: Path) -> str:
    """The name of the layout ``root`` holds (``scannetpp_iphone``, ``prepared``, ``generic``, ``scannetpp_dslr``)."""
    for layout in LAYOUTS:
        if layout.detect(root):
            return layout.name
    looked = "; ".join(f"{lay.name}: {lay.looks_for}" for lay in LAYOUTS)
    raise InputError(root, f"no known scene layout (looked for {looked})")


def load_scene(path: str | Path, selection: FrameSelectionConfig | None = None, *,
               layout: str | None = None, scannetpp_world: bool | None = None,
               cache_dir: str | Path | None = None, rasterizer: Callable[[Path], Rasterizer] | None = None,
               memo: SelectionMemo | None = None) -> SceneInput:
    """Load any registered layout (auto-detected unless ``layout`` names one), then select frames.

    ``cache_dir`` (DSLR only; default ``<scene>/.react3d_cache``) receives undistorted images and rendered depth.
    ``scannetpp_world`` (generic nerfstudio only): poses in ScanNet++'s permuted world; None decides by location.
    ``rasterizer(mesh_path)`` gives the scan's :class:`~react3d_core.raster.Rasterizer` for the coverage rule
    of keyframe selection (default: built from the mesh here; callers that keep one pass theirs);
    ``memo`` remembers keyframe selections by content, so a re-run does not render the frames again."""
    root = Path(path)
    if not root.is_dir():
        raise InputError(root, "scene folder not found")
    spec = layout_named(layout or detect_layout(root), root)
    chosen: list[FrameSelection] = []

    def select(frames: Sequence[Frame], mesh: Path) -> list[Frame]:
        if selection is None:
            return list(frames)

        def raster() -> Rasterizer:
            return rasterizer(mesh) if rasterizer is not None else _default_rasterizer(mesh)

        chosen.append(choose_frames_memo(frames, selection, mesh, raster, memo))
        return chosen[-1].frames

    scene = spec.load(root, LoadOptions(select=select, cache_dir=Path(cache_dir) if cache_dir else None,
                                        scannetpp_world=scannetpp_world))
    if selection is not None and not spec.selects_frames:
        scene = scene.model_copy(update={"frames": tuple(select(scene.frames, scene.mesh_path))})
    if chosen:
        scene = scene.model_copy(update={"frame_selection": chosen[-1].reason})
    return scene


def _default_rasterizer(mesh_path: Path) -> Rasterizer:
    from ..data.mesh import load_mesh

    return Rasterizer(load_mesh(mesh_path))
