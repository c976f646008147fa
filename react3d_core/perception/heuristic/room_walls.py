"""Fronts on the room's outer walls: only room doors stand there.

A scan is taken from inside a room, so nothing behind its outer walls is scanned. Cabinets stand in
front of a wall: the wall above a base run, below wall cabinets or above a wardrobe, the floor running
under a unit, lies behind their fronts' plane. A front whose plane has (almost) no scan surface more
than ``depth`` behind it is therefore painted on an outer wall (or hung on it: a radiator, a picture a few
cm proud of the wall, whose wall within ``wall_band`` behind counts as its plane's), and there the wall's paint, the seams
between views fused at different exposures, a skirting board or a light switch make cells and "handles"
(on the tuning scenes 51 of 102 false fronts, and 0 of the true cabinet fronts, had nothing behind
them). The only openable thing set into an outer wall is a room door — floor to door height, door
wide — so such a front is kept only when shaped like one, and then typed as a side-hinged door (its
lever handle is horizontal, which the shape rules read as a bottom-hinged oven door). A scan with no
surface behind any plane at all (a lone cabinet scanned from the front only) has no wall to tell
apart: ``min_area`` of other surface in the plane, not in any front, is required as well. The thresholds
are ``perception.heuristic.room_wall``.
"""

from __future__ import annotations

import numpy as np

from ...config.heuristic import FloorConfig, FrontRulesConfig, RoomWallConfig
from ...data.mesh import TriMesh
from .fronts import Front, _joint, _neighbours
from .image_fronts import floor_level
from .planes import share_behind


def on_outer_wall(fronts: list[Front], mesh: TriMesh, rules: RoomWallConfig) -> list[bool]:
    """Per front: does its plane have less than ``behind_share`` of the scan's area more than ``depth``
    behind it (the wall's own outer side, ``wall_back``, left out), with at least ``min_area`` of other
    surface in the plane (within ``plane_tol``, facing the same way, or up to ``wall_band`` behind it; see
    module docstring)?"""
    if not fronts:
        return []
    cen, area, nrm = mesh.face_centroids, mesh.face_areas, mesh.face_normals
    in_front = np.zeros(mesh.n_faces, bool)
    for f in fronts:
        in_front[f.faces] = True
    out = []
    for f in fronts:
        d = (cen - f.center) @ f.n_out
        behind = share_behind(  # a modelled wall's own outer side is left out (planes.share_behind)
            mesh, f.n_out, float(f.center @ f.n_out), rules.depth, rules.wall_back, rules.plane_min_cos)
        wall = (d > -max(rules.plane_tol, rules.wall_band)) & (d < rules.plane_tol) & (nrm @ f.n_out > rules.plane_min_cos) & ~in_front
        out.append(behind < rules.behind_share and float(area[wall].sum()) >= rules.min_area)
    return out


def room_door_shaped(f: Front, floor: float, rules: RoomWallConfig) -> bool:
    """Floor to door height, door wide."""
    return (f.h >= rules.door_min_h and rules.door_w[0] <= f.w <= rules.door_w[1]
            and f.extent_v[0] <= floor + rules.door_floor_gap)


def keep_room_doors(fronts: list[Front], mesh: TriMesh, rules: RoomWallConfig, front_rules: FrontRulesConfig,
                    floor_cfg: FloorConfig, facet_labels: np.ndarray | None = None) -> list[Front]:
    """``fronts`` less those on an outer wall that are not shaped like a room door (the floor by
    ``floor_cfg``); the room doors kept are re-typed as side-hinged doors (hinge away from the handle).
    ``facet_labels``: the mesh's facet per face, for the handle of a front found on the mesh (its
    ``handle_facets``). (The rule itself, whether or not ``rules.enabled``.)"""
    wall = on_outer_wall(fronts, mesh, rules)
    if not any(wall):
        return list(fronts)
    floor = floor_level(mesh, floor_cfg)
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
    return mesh.vertices[mesh.faces[faces]].reshape(-1, mesh.vertices.shape[1]) if len(faces) else None
