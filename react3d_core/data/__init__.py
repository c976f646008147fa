"""Data contracts shared by all stages (pydantic v2 models + array file I/O)."""

from .frames import Frame, ImageRef, Intrinsics, SceneInput, validate_pose
from .masks import ArticulationPrediction, Mask2D, load_masks, save_masks
from .mesh import TriMesh, load_mesh, save_mesh
from .parts import (
    OBB,
    Articulation,
    InteractiveObject,
    InteractiveScene,
    PartCandidate,
    TopView,
    load_vertex_ids,
    save_vertex_ids,
)

__all__ = [
    "OBB",
    "Articulation",
    "ArticulationPrediction",
    "Frame",
    "ImageRef",
    "InteractiveObject",
    "InteractiveScene",
    "Intrinsics",
    "Mask2D",
    "PartCandidate",
    "SceneInput",
    "TopView",
    "TriMesh",
    "load_masks",
    "load_mesh",
    "load_vertex_ids",
    "save_masks",
    "save_mesh",
    "save_vertex_ids",
    "validate_pose",
]
