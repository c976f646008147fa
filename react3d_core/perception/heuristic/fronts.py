"""Openable fronts from planar facets: vertical, rectangular, door/drawer-sized, seen by the cameras,
with a handle in front of them or a coplanar neighbour front — and a joint guessed from shape + handle.

Rules (a heuristic, see docs/perception.md for its limits):
- type: a horizontal handle on a low front (h <= ``drawer_max_h``) or a low handle-less front that is
  wide or stacked with a same-width front -> drawer (prismatic, pulled along the front normal); a
  horizontal handle low on a tall front ->
  top-hinged flap; high on a tall front -> bottom-hinged drop door; otherwise a vertical hinge;
- hinge side: opposite the handle; without a handle, away from an adjacent coplanar neighbour of the
  same height (door pairs), else the left edge.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...data.mesh import TriMesh
from ...data.parts import Articulation
from .facets import Facets


@dataclass(frozen=True)
class FrontRules:
    min_w: float = 0.12
    max_w: float = 1.3
    min_h: float = 0.1
    max_h: float = 2.3
    max_tilt: float = 0.25            # |n_z| of a vertical front
    min_fill: float = 0.8             # facet area / bounding rectangle
    handle_max_area: float = 0.03     # m^2 of one handle facet
    handle_depth: tuple[float, float] = (0.002, 0.09)  # handle facets in front of the plane (m)
    drawer_max_h: float = 0.42
    neighbour_gap: float = 0.03


@dataclass
class Front:
    """One openable front: its facet, handle facets, frame (u right, v up, n out) and joint guess."""

    facet: int
    handle_facets: list[int]
    center: np.ndarray
    n_out: np.ndarray
    u: np.ndarray
    extent_u: tuple[float, float]
    extent_v: tuple[float, float]
    articulation: Articulation | None = None
    kind: str = ""
    faces: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    @property
    def w(self) -> float:
        return self.extent_u[1] - self.extent_u[0]

    @property
    def h(self) -> float:
        return self.extent_v[1] - self.extent_v[0]


def _frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    nh = np.array([n[0], n[1], 0.0])
    nh /= max(np.linalg.norm(nh), 1e-12)
    u = np.cross([0.0, 0.0, 1.0], nh)  # right-hand side when looking at the front from the room
    return nh, u / np.linalg.norm(u)


def find_fronts(mesh: TriMesh, facets: Facets, visible: np.ndarray, cam_center: np.ndarray,
                rules: FrontRules = FrontRules()) -> list[Front]:
    """Fronts among facets with ``visible[facet]`` True; ``cam_center`` orients normals to the room."""
    fv = mesh.vertices[mesh.faces]                       # (F,3,3)
    fc = fv.mean(1)
    order = np.argsort(facets.labels, kind="stable")
    starts = np.searchsorted(facets.labels[order], np.arange(facets.n + 1))
    faces_of = lambda k: order[starts[k]:starts[k + 1]]  # noqa: E731
    fa = np.zeros((facets.n, 3))
    _, areas = _areas(mesh)
    np.add.at(fa, facets.labels, fc * areas[:, None])
    fcent = fa / np.maximum(facets.areas, 1e-15)[:, None]

    cands: list[Front] = []
    for k in np.flatnonzero(visible & (np.abs(facets.normals[:, 2]) <= rules.max_tilt) & (facets.areas >= rules.min_w * rules.min_h)):
        n = facets.normals[k]
        if np.dot(n, cam_center - fcent[k]) < 0:
            n = -n
        nh, u = _frame(n)
        pts = fv[faces_of(k)].reshape(-1, 3)
        pu, pv = pts @ u, pts[:, 2]
        eu, ev = (float(pu.min()), float(pu.max())), (float(pv.min()), float(pv.max()))
        w, h = eu[1] - eu[0], ev[1] - ev[0]
        if not (rules.min_w <= w <= rules.max_w and rules.min_h <= h <= rules.max_h):
            continue
        if facets.areas[k] < rules.min_fill * w * h:
            continue
        cands.append(Front(int(k), [], fcent[k], nh, u, eu, ev))
    if not cands:
        return []
    cands = _drop_covered(cands)
    # handles: small visible facets just in front of a candidate, inside its rectangle (nearest plane wins)
    small = np.flatnonzero(visible & (facets.areas <= rules.handle_max_area))
    if len(small):
        c = fcent[small]                                                     # (S,3)
        centers = np.array([f.center for f in cands])                        # (C,3)
        normals = np.array([f.n_out for f in cands])
        us = np.array([f.u for f in cands])
        eu = np.array([f.extent_u for f in cands])
        ev = np.array([f.extent_v for f in cands])
        d = np.einsum("scx,cx->sc", c[:, None, :] - centers[None], normals)   # depth in front of each plane
        cu, cv = c @ us.T, c[:, 2:3]
        ok = ((rules.handle_depth[0] < d) & (d < rules.handle_depth[1])
              & (eu[:, 0] + 0.005 < cu) & (cu < eu[:, 1] - 0.005) & (ev[:, 0] + 0.005 < cv) & (cv < ev[:, 1] - 0.005))
        d = np.where(ok, d, np.inf)
        best = d.argmin(1)
        for s_id, k in zip(small[np.isfinite(d.min(1))], best[np.isfinite(d.min(1))]):
            cands[k].handle_facets.append(int(s_id))
    out = []
    for f in cands:
        neighbours = _neighbours(f, cands, rules)
        if not f.handle_facets and not neighbours:
            continue  # a lone plain panel (a cabinet side, a wall piece): not openable by these rules
        hf = np.concatenate([faces_of(s) for s in f.handle_facets]) if f.handle_facets else np.zeros(0, np.int64)
        f.faces = np.concatenate([faces_of(f.facet), hf])
        hpts = fv[hf].reshape(-1, 3) if len(hf) else None
        f.kind, f.articulation = _joint(f, hpts, neighbours, rules)
        out.append(f)
    return out


def _drop_covered(cands: list[Front]) -> list[Front]:
    """Drop a facet that other candidates cover from the front (a carcass face seen through the gaps)."""
    keep = []
    for f in cands:
        covered = 0.0
        for g in cands:
            if g is f or np.dot(g.n_out, f.n_out) < 0.97 or not (0.001 < np.dot(g.center - f.center, f.n_out) < 0.08):
                continue
            gu0, gu1 = float(g.center @ f.u) - g.w / 2, float(g.center @ f.u) + g.w / 2
            ou = max(0.0, min(gu1, f.extent_u[1]) - max(gu0, f.extent_u[0]))
            ov = max(0.0, min(g.extent_v[1], f.extent_v[1]) - max(g.extent_v[0], f.extent_v[0]))
            covered += ou * ov
        if covered < 0.5 * f.w * f.h:
            keep.append(f)
    return keep


def _areas(mesh: TriMesh) -> tuple[np.ndarray, np.ndarray]:
    t = mesh.vertices[mesh.faces]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return n, 0.5 * np.linalg.norm(n, axis=1)


def _neighbours(f: Front, cands: list[Front], r: FrontRules) -> list[tuple[Front, str]]:
    """Coplanar candidates touching ``f`` on its left/right (same height) or above/below (same width)."""
    out = []
    for g in cands:
        if g is f or np.dot(g.n_out, f.n_out) < 0.97 or abs(np.dot(g.center - f.center, f.n_out)) > 0.03:
            continue
        gu = (float(g.center @ f.u) - g.w / 2, float(g.center @ f.u) + g.w / 2)
        same_rows = abs(g.extent_v[0] - f.extent_v[0]) < 0.05 and abs(g.extent_v[1] - f.extent_v[1]) < 0.05
        same_cols = abs(gu[0] - f.extent_u[0]) < 0.05 and abs(gu[1] - f.extent_u[1]) < 0.05
        if same_rows and 0 <= gu[0] - f.extent_u[1] < r.neighbour_gap:
            out.append((g, "right"))
        elif same_rows and 0 <= f.extent_u[0] - gu[1] < r.neighbour_gap:
            out.append((g, "left"))
        elif same_cols and (0 <= g.extent_v[0] - f.extent_v[1] < r.neighbour_gap or 0 <= f.extent_v[0] - g.extent_v[1] < r.neighbour_gap):
            out.append((g, "vertical"))
    return out


def _opening_sign(axis: np.ndarray, origin: np.ndarray, probe: np.ndarray, n_out: np.ndarray) -> np.ndarray:
    """Flip ``axis`` so that a small positive rotation moves ``probe`` out along ``n_out``."""
    a = Articulation(joint_type="revolute", axis=axis, origin=origin, lower=0.0, upper=1.0)
    moved = a.move(probe[None], 0.1)[0]
    return axis if np.dot(moved - probe, n_out) > 0 else -axis


def _joint(f: Front, hpts: np.ndarray | None, neighbours: list[tuple[Front, str]], r: FrontRules) -> tuple[str, Articulation]:
    z = np.array([0.0, 0.0, 1.0])
    cu, cv = 0.5 * sum(f.extent_u), 0.5 * sum(f.extent_v)
    plane_pt = f.center
    on_plane = lambda uu, vv: plane_pt + f.u * (uu - float(plane_pt @ f.u)) + z * (vv - plane_pt[2])  # noqa: E731
    centre = on_plane(cu, cv)
    if hpts is not None:
        hu, hv = hpts @ f.u, hpts[:, 2]
        horizontal = np.ptp(hu) >= np.ptp(hv)
        hcu, hcv = float(hu.mean()), float(hv.mean())
    else:
        horizontal, hcu, hcv = None, cu, cv
    stacked = any(side == "vertical" for _, side in neighbours)  # a same-width front above/below: a stack
    if (horizontal and f.h <= r.drawer_max_h) or (hpts is None and f.h <= r.drawer_max_h and (f.w >= f.h or stacked)):
        return "drawer", Articulation(joint_type="prismatic", axis=f.n_out, origin=centre, lower=0.0, upper=0.3,
                                      limit_source="heuristic")
    if horizontal:
        low = hcv < cv
        edge_v = f.extent_v[1] if low else f.extent_v[0]  # flap: hinge on top; drop door: hinge at the bottom
        origin = on_plane(cu, edge_v)
        probe = on_plane(cu, f.extent_v[0] if low else f.extent_v[1])
        axis = _opening_sign(f.u.copy(), origin, probe, f.n_out)
        return ("flap" if low else "drop"), Articulation(joint_type="revolute", axis=axis, origin=origin, lower=0.0,
                                                        upper=float(np.radians(90)), limit_source="heuristic")
    if hpts is not None:
        hinge_left = hcu > cu
    else:
        sides = {s for _, s in neighbours}
        hinge_left = not ("left" in sides and "right" not in sides)
    edge_u = f.extent_u[0] if hinge_left else f.extent_u[1]
    origin = on_plane(edge_u, cv)
    probe = on_plane(f.extent_u[1] if hinge_left else f.extent_u[0], cv)
    axis = _opening_sign(z.copy(), origin, probe, f.n_out)
    return "door", Articulation(joint_type="revolute", axis=axis, origin=origin, lower=0.0,
                                upper=float(np.radians(100)), limit_source="heuristic")
