"""A chest's front with a bar at its top is the lid's lip, not a bottom-hinged door.

A chest freezer (or a chest, a toy box) opens by a lid hinged at the back of its top; its bar sits on the
lid's front lip. The image rules see a wide plain panel (the chest's body and the lip, one plane) with a
horizontal bar near its top and type it a bottom-hinged drop door, which is no part at all. A real drop
door (dishwasher, oven) is at most ~0.6 m wide, and above it is a control panel or a worktop that runs on
past its sides; a chest's lid is a flat top level with the front's top edge, as wide and no wider, that
reaches back the chest's depth. So a drop-typed front at least ``min_w`` wide becomes the lid when an
upward-facing surface lies level with its top edge (within ``band``), covers ``cover`` of the rectangle
``min_depth`` deep behind it, and covers under ``side_cover`` of the strips ``side`` wide beside it; the lid
is that top with the lip below it (``lip``) and turns about its back edge, opening upwards
(``perception.heuristic.lids``).
"""

from __future__ import annotations

import numpy as np

from ...config.heuristic import LidConfig
from ...data.mesh import TriMesh
from ...data.parts import Articulation
from .fronts import Front

_UP = np.array([0.0, 0.0, 1.0])
_DEPTH_PERCENTILE = 99  # the lid reaches back as far as the top's faces, stray ones left out


def chest_lids(fronts: list[Front], mesh: TriMesh, rules: LidConfig, max_deg: float) -> list[int]:
    """Turns the drop-typed fronts that are a chest's lip into the chest's lid (see module docstring), in
    place: their faces become the lid's, their kind ``lid``, their joint revolute about the back edge of
    the top, opening upwards by ``max_deg``. Returns the indices of the fronts turned."""
    if not fronts or not rules.enabled:
        return []
    n = mesh.face_normals
    cen, area = mesh.face_centroids, mesh.face_areas
    up = np.flatnonzero(n[:, 2] > rules.min_up)
    turned = []
    for k, f in enumerate(fronts):
        if f.kind != "drop" or f.w < rules.min_w:
            continue
        top = float(f.extent_v[1])
        plane_d = float(f.center @ f.n_out)
        back = plane_d - cen[up] @ f.n_out  # how far behind the front's plane
        cu = cen[up] @ f.u
        level = np.abs(cen[up, 2] - top) < rules.band
        over = level & (cu > f.extent_u[0]) & (cu < f.extent_u[1]) & (back > -rules.band)
        deep = over & (back < rules.min_depth)
        if area[up][deep].sum() < rules.cover * f.w * rules.min_depth:
            continue
        beside = level & (back > -rules.band) & (back < rules.min_depth) & (
            ((cu > f.extent_u[0] - rules.side) & (cu < f.extent_u[0] - rules.band))
            | ((cu > f.extent_u[1] + rules.band) & (cu < f.extent_u[1] + rules.side)))
        if area[up][beside].sum() >= rules.side_cover * 2 * (rules.side - rules.band) * rules.min_depth:
            continue  # a worktop running on past its sides: a drop door under it
        top_faces = up[over & (back < rules.max_depth)]
        z_top = float(np.median(cen[top_faces, 2]))
        depth = float(np.percentile(plane_d - cen[top_faces] @ f.n_out, _DEPTH_PERCENTILE))
        cu_all, back_all = cen @ f.u, plane_d - cen @ f.n_out
        lid = np.flatnonzero((cu_all > f.extent_u[0] - rules.band) & (cu_all < f.extent_u[1] + rules.band)
                             & (back_all > -rules.band) & (back_all < depth + rules.band)
                             & (cen[:, 2] > z_top - rules.lip) & (cen[:, 2] < z_top + rules.band))
        origin = f.center + _UP * (z_top - float(f.center[2])) - f.n_out * depth  # the middle of the back edge
        axis = np.cross(f.n_out, _UP)  # turning about it lifts the front edge (+n_out from the hinge) upwards
        f.faces = np.union1d(lid, f.faces[cen[f.faces, 2] > z_top - rules.lip])
        f.kind = "lid"
        f.articulation = Articulation(joint_type="revolute", axis=axis, origin=origin, lower=0.0,
                                      upper=float(np.radians(max_deg)), limit_source="heuristic")
        turned.append(k)
    return turned
