"""What the articulation stage hands to assembly: one validated, refined movable part."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.parts import OBB, Articulation


@dataclass
class ArticulatedPart:
    """A candidate that passed validation, with its initial (predicted) and refined joints.

    ``front_normal`` points from the front face into the cavity (away from the room);
    ``thickness`` is the front slab's thickness along it (handles excluded); ``sliding``: a prismatic
    part that moves in its front plane (sliding door), so assembly gives it no drawer box and a travel
    along its own width.
    """

    candidate_id: int
    label: str
    score: float
    face_ids: np.ndarray
    vertex_ids: np.ndarray
    initial: Articulation
    articulation: Articulation
    obb: OBB
    front_normal: np.ndarray
    thickness: float
    flat: bool
    seg_frame_id: str | None = None
    top_views: list[dict] = field(default_factory=list)
    validation_iou: float = 0.0
    sliding: bool = False
