"""Synthetic scenes with exact ground truth, written in the ScanNet++ iPhone layout.

Sources: ``procedural`` (our rooms: kitchens, wardrobes, dressers, room doors, and rooms of free-standing
furniture and appliances, glass-panel doors and dark fronts), ``scene-synthesizer`` (its procedural
kitchens) and ``urdf`` (any articulated URDF). Same arguments -> same bytes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .depth_effects import DEPTH_DROPOUT
from .materials import REALISM
from .procedural import ALL_KINDS, KINDS, SynthLayout, build_room
from .remesh import MESH_KINDS
from .writer import GENERATOR_VERSION, write_synthetic

STAGE_VERSION = GENERATOR_VERSION
SOURCES = ("procedural", "scene-synthesizer", "urdf")
__all__ = ["ALL_KINDS", "DEPTH_DROPOUT", "KINDS", "MESH_KINDS", "REALISM", "SOURCES", "STAGE_VERSION", "build_room", "demo_scene",
           "generate_scene"]


def _room_depths(layout: SynthLayout) -> list[float]:
    W, L, _ = layout.room
    return [r.free_depth if r.free_depth is not None else (L if abs(np.sin(r.frame.theta)) < 0.5 else W)
            for r in layout.runs]


def generate_scene(out_dir: str | Path, source: str = "procedural", seed: int = 0, n_frames: int = 60,
                   urdf_path: str | Path | None = None, kind: str | None = None, edge: float | None = None,
                   mesh: str = "clean", realism: str = "photo", misregister: tuple[float, float] = (0.0, 0.0),
                   up: str = "z", scale: float = 1.0, depth_dropout: str = "none", decimate: float = 1.0) -> Path:
    """Build, render and write one synthetic scene; returns ``out_dir``.

    ``kind`` picks the procedural room type (default by seed), ``edge`` the triangle size of the
    furniture (smaller = denser meshes, for scaling benchmarks; default 3 cm procedural, 5 cm others).
    ``mesh`` (clean | laser | tsdf) re-makes the written scan mesh like a real scan, ``realism``
    (photo | plain) picks the image renderer, ``misregister`` shifts colour against depth by (dx, dy)
    pixels, ``decimate`` keeps that share of a laser / TSDF mesh's faces (quadric; see
    :func:`.writer.write_synthetic`). ``up`` / ``scale`` (urdf only): the asset's up axis
    and unit scale (:func:`.from_urdf.build_from_urdf`). ``depth_dropout`` (none | dark): drop depth on
    dark and glossy surfaces like a ToF sensor, in the depth frames and the laser / TSDF mesh
    (:mod:`.depth_effects`).
    """
    if source != "urdf" and (up != "z" or scale != 1.0):
        raise ValueError("up/scale apply to source='urdf' only")
    edge = edge if edge is not None else (0.03 if source == "procedural" else 0.05)
    if source == "procedural":
        layout = build_room(seed, kind, edge=edge)
    elif source == "scene-synthesizer":
        from .from_scene_synthesizer import build_scene_synthesizer

        layout = build_scene_synthesizer(seed, edge=edge)
    elif source == "urdf":
        if urdf_path is None:
            raise ValueError("source='urdf' needs urdf_path")
        from .from_urdf import build_from_urdf

        layout = build_from_urdf(Path(urdf_path), seed, edge=edge, up=up, scale=scale)
    else:
        raise ValueError(f"unknown source {source!r}; choose from {', '.join(SOURCES)}")
    return write_synthetic(layout, out_dir, n_frames, seed, source, room_depths=_room_depths(layout), mesh=mesh,
                           realism=realism, misregister=misregister, depth_dropout=depth_dropout, decimate=decimate)


def demo_scene(out_dir: str | Path) -> Path:
    """The built-in demo: a small kitchen, 48 frames (a few seconds to generate)."""
    return generate_scene(out_dir, source="procedural", seed=3, n_frames=48, kind="kitchen")
