"""Fronts on the room's outer walls: only room doors stand there.

A scan is taken from inside a room, so nothing behind its outer walls is scanned. Cabinets stand in
front of a wall: the wall above a base run, below wall cabinets or above a wardrobe, the floor running
under a unit, lies behind their fronts' plane. A front whose plane has (almost) no scan surface more
than ``depth`` behind it is therefore painted on an outer wall, and there the wall's paint, the seams
between views fused at different exposures, a skirting board or a light switch make cells and "handles"
(on the tuning scenes 51 of 102 false fronts, and 0 of the true cabinet fronts, had nothing behind
them). The only openable thing set into an outer wall is a room door — floor to door height, door
wide — so such a front is kept only when shaped like one, and then typed as a side-hinged door (its
lever handle is horizontal, which the shape rules read as a bottom-hinged oven door). A scan with no
surface behind any plane at all (a lone cabinet scanned from the front only) has no wall to tell
apart: ``min_wall_area`` of other surface in the plane, not in any front, is required as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...config.heuristic import HeuristicConfig
from ...data.mesh import TriMesh
from .fronts import Front, FrontRules, _joint, _neighbours
from .image_fronts import floor_level

_H = HeuristicConfig()


@dataclass(frozen=True)
class RoomWallRules:
    """Built from ``HeuristicConfig`` (perception.heuristic.room_wall_* / room_door_*)."""

    behind_share: float = _H.room_wall_behind_share  # share of the scan's area behind the plane below which it is an outer wall
    depth: float = _H.room_wall_depth                # m behind the plane that counts as behind
    min_wall_area: float = _H.room_wall_min_area     # m² of surface in the plane outside every front
    door_min_h: float = _H.room_door_min_h           # m: a room door is at least this tall ...
    door_w: tuple[float, float] = tuple(_H.room_door_w)  # ... this wide (m) ...
    floor_gap: float = _H.room_door_floor_gap        # ... and reaches this close to the floor (m)
    floor_min_area: float = _H.floor_min_area        # m²: upward-facing area that makes a 2 cm band the floor


def room_wall_from_config(cfg: HeuristicConfig) -> RoomWallRules | None:
    """The rules, or None when ``perception.heuristic.room_wall`` is off."""
    if not cfg.room_wall:
        return None
    return RoomWallRules(cfg.room_wall_behind_share, cfg.room_wall_depth, cfg.room_wall_min_area, cfg.room_door_min_h,
                         tuple(cfg.room_door_w), cfg.room_door_floor_gap, cfg.floor_min_area)


def on_outer_wall(fronts: list[Front], mesh: TriMesh, rules: RoomWallRules) -> list[bool]:
    """Per front: does its plane have less than ``behind_share`` of the scan's area more than ``depth``
    behind it, with at least ``min_wall_area`` of other surface in the plane (see module docstring)?"""
    if not fronts:
        return []
    cen, area, nrm = mesh.face_centroids, mesh.face_areas, mesh.face_normals
    total = max(float(area.sum()), 1e-12)
    in_front = np.zeros(mesh.n_faces, bool)
    for f in fronts:
        in_front[f.faces] = True
    out = []
    for f in fronts:
        d = (cen - f.center) @ f.n_out
        behind = float(area[d < -rules.depth].sum()) / total
        wall = (np.abs(d) < 0.03) & (nrm @ f.n_out > 0.9) & ~in_front
        out.append(behind < rules.behind_share and float(area[wall].sum()) >= rules.min_wall_area)
    return out


def room_door_shaped(f: Front, floor: float, rules: RoomWallRules) -> bool:
    """Floor to door height, door wide."""
    return (f.h >= rules.door_min_h and rules.door_w[0] <= f.w <= rules.door_w[1]
            and f.extent_v[0] <= floor + rules.floor_gap)


def keep_room_doors(fronts: list[Front], mesh: TriMesh, rules: RoomWallRules, front_rules: FrontRules,
                    facet_labels: np.ndarray | None = None) -> list[Front]:
    """``fronts`` less those on an outer wall that are not shaped like a room door; the room doors kept
    are re-typed as side-hinged doors (hinge away from the handle). ``facet_labels``: the mesh's facet
    per face, for the handle of a front found on the mesh (its ``handle_facets``)."""
    wall = on_outer_wall(fronts, mesh, rules)
    if not any(wall):
        return list(fronts)
    floor = floor_level(mesh, rules.floor_min_area)
    door = [w and room_door_shaped(f, floor, rules) for f, w in zip(fronts, wall)]
    kept = [f for f, w, d in zip(fronts, wall, door) if d or not w]
    for f in (f for f, d in zip(fronts, door) if d):
        f.kind, f.articulation = _joint(f, _handle_points(f, mesh, facet_labels), _neighbours(f, kept, front_rules),
                                        front_rules, side_hinged=True)
    return kept


def _handle_points(f: Front, mesh: TriMesh, facet_labels: np.ndarray | None) -> np.ndarray | None:
    """The front's handle: seen in the images, else its scanning shadow, else its handle facets' vertices."""
    for pts in (f.handle_points, f.shadow_points):
        if pts is not None and len(pts):
            return pts
    if facet_labels is None or not f.handle_facets:
        return None
    faces = f.faces[np.isin(facet_labels[f.faces], f.handle_facets)]
    return mesh.vertices[mesh.faces[faces]].reshape(-1, 3) if len(faces) else None
