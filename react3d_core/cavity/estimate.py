"""Hidden geometry behind a movable part: cavity depth d_in = min(d_image, d_hit, d_mesh, d_body), the base
(an open, double-walled box behind the front) and, for drawers, an inner box that moves with the part.

- d_hit: rays from the slab's mid-surface into the cavity (centre and 4 points at 0.1 x the longest
  edge), starting beyond 2 x the slab thickness so the part itself is not hit; the median hit;
- d_image: the farthest scene depth behind the front plane seen around the part in the segmenting frame
  (an upper bound: the wall behind a wall cabinet), used when at least two sides of that band mostly
  see behind it;
- d_mesh: where the ray leaves the scan's bounding box;
- d_body: the furniture's own depth, for when nothing is seen behind it (a free-standing chest whose back
  no camera saw: d_hit then reaches the room wall 2 m away and a drawer got 1.18 m of travel in a
  0.37 m chest; a wall cabinet whose wall no camera saw behind it). Rays cast straight up
  from points ever deeper behind the front hit the carcass top or worktop at about the same distance
  while they are inside the furniture (down to a wall cabinet's bottom board when nothing is above;
  sideways to its own side panels when neither profile ends, a tall unit whose top no camera saw);
  the first depth where the hit jumps by ``body_jump_m`` (or vanishes) is past its back.
Depths are measured from the slab's back face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..camera import unproject
from ..config import CavityConfig
from ..data.frames import Frame
from ..data.mesh import TriMesh
from ..geometry import concat_meshes, triangle_cross

UP = np.array([0.0, 0.0, 1.0])  # world = scan frame, z up (data/frames.py conventions)


@dataclass
class PartFrame:
    """The front slab's frame: centre on the mid-surface, in-plane axes/extents, normal into the cavity."""

    center: np.ndarray
    u: np.ndarray
    v: np.ndarray
    n: np.ndarray
    su: float
    sv: float
    thickness: float

    @property
    def back(self) -> np.ndarray:
        return self.center + self.n * self.thickness / 2


def d_hit(pf: PartFrame, cast: callable, cfg: CavityConfig) -> float:  # type: ignore[valid-type]
    r = cfg.search_radius_factor * max(pf.su, pf.sv)
    offs = [np.zeros(3), r * pf.u, -r * pf.u, r * pf.v, -r * pf.v]
    skip = max(cfg.ignore_hits_thickness_factor * pf.thickness, 0.005)
    origins = np.array([pf.center + o + pf.n * skip for o in offs])
    t = np.asarray(cast(origins, np.tile(pf.n, (len(origins), 1))), float)
    t = t[np.isfinite(t)]
    if len(t) == 0:
        return np.inf
    return float(np.median(t) + skip - pf.thickness / 2)


def d_mesh(pf: PartFrame, bounds: np.ndarray) -> float:
    """Distance from the back face along n to the scan's bounding box."""
    o, n = pf.back, pf.n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(n > 1e-9, (bounds[1] - o) / n, np.where(n < -1e-9, (bounds[0] - o) / n, np.inf))
    return float(max(0.0, t.min()))


def d_image(pf: PartFrame, frame: Frame | None, depth: np.ndarray | None, cfg: CavityConfig) -> float:
    """Farthest depth behind the front plane in a band around the part (segmenting frame)."""
    if frame is None or depth is None or frame.depth_intrinsics is None:
        return np.inf
    pw = unproject(depth, frame.depth_intrinsics.K, frame.c2w)[depth > 0]
    rel = pw - pf.back
    a, b, c = rel @ pf.u, rel @ pf.v, rel @ pf.n
    inner = (np.abs(a) <= 0.5 * pf.su) & (np.abs(b) <= 0.5 * pf.sv)
    band = (np.abs(a) <= 0.65 * pf.su) & (np.abs(b) <= 0.65 * pf.sv) & ~inner
    deep = band & (c > 0.02)
    behind = c[deep]
    # only a real view past the furniture (a wall around a wall cabinet) bounds the depth: deep pixels
    # on at least two sides of the part, each side mostly deep; a toe-kick recess below a bottom
    # drawer or the gaps between drawers see only one side or a sliver
    sides = [a < -0.5 * pf.su, a > 0.5 * pf.su, b < -0.5 * pf.sv, b > 0.5 * pf.sv]
    seen = sum(1 for sd in sides if (band & sd).sum() > 0 and (deep & sd).sum() >= 0.5 * (band & sd).sum())
    if band.sum() == 0 or len(behind) < 0.2 * band.sum() or seen < 2:
        return np.inf
    return float(behind.max())


def _profile_end(pf: PartFrame, cast: callable, cs: np.ndarray, spread: np.ndarray, axis: np.ndarray,  # type: ignore[valid-type]
                 d: np.ndarray, cfg: CavityConfig) -> tuple[float, float]:
    """(reference hit distance, depth where the body ends) of the rays along ``d`` from points at depths
    ``cs`` behind the back face, spread by ``spread`` along ``axis`` (median per depth). The reference is
    the median of the first three depths (inf: nothing there); the body ends half a step before the first
    depth whose hit is ``body_jump_m`` farther or missing (inf: no such depth)."""
    origins = (pf.back + cs[:, None, None] * pf.n + spread[None, :, None] * axis).reshape(-1, 3)
    t = np.asarray(cast(origins, np.tile(d, (len(origins), 1))), float).reshape(len(cs), len(spread))
    t = np.median(np.where(np.isfinite(t), t, np.inf), axis=1)
    t0 = float(np.median(t[:3]))
    if not np.isfinite(t0):
        return np.inf, np.inf
    out = np.flatnonzero(~(t <= t0 + cfg.body_jump_m))
    out = out[out >= 3]
    return t0, (float(cs[out[0]] - 0.5 * cfg.body_step_m) if len(out) else np.inf)


def d_body(pf: PartFrame, cast: callable, cfg: CavityConfig, up: np.ndarray = UP,  # type: ignore[valid-type]
           floor: float = -np.inf) -> float:
    """Depth behind the back face at which the furniture around the part ends (inf if not found).

    Rays straight up from 3 points across the part's width, at depths ``body_step_m`` apart, hit the
    carcass top or worktop at about the same distance while inside the body (:func:`_profile_end`).
    Only when nothing at all is above the part (a wall cabinet whose top no camera saw) are rays cast
    down instead, to its bottom board: below a base unit they would follow plinths and toe-kicks (on a
    scene-synthesizer kitchen they cut two 0.69 m base cavities to 0.19 m), and they count only when they
    hit above ``floor`` + ``body_floor_m`` (the floor under furniture was never seen: where its scan ends
    is not where the body does). Where neither profile ends
    (a tall unit whose top is above every camera: up-rays reach the ceiling inside and behind it alike),
    rays sideways from 3 points up the part's height do, if they hit the part's own side panels (within
    half its width + ``body_side_reach_m``; a unit inside a run sees no panel of its own there): the
    nearer side that ends is the body's depth. Fronts facing up or down (flaps in a worktop) have no
    such profile."""
    up = np.asarray(up, float) / np.linalg.norm(up)
    if abs(float(np.dot(pf.n, up))) > 0.5:
        return np.inf
    side = pf.u if abs(np.dot(pf.u, up)) <= abs(np.dot(pf.v, up)) else pf.v  # horizontal in-plane axis
    width, height = (pf.su, pf.sv) if side is pf.u else (pf.sv, pf.su)
    vertical = np.cross(pf.n, side)
    start = max(cfg.ignore_hits_thickness_factor * pf.thickness, 0.02)
    cs = np.arange(start, cfg.max_depth_m + cfg.body_step_m, cfg.body_step_m)
    if len(cs) < 4:
        return np.inf
    lat = np.array([-cfg.body_lateral_factor, 0.0, cfg.body_lateral_factor])
    t0, end = _profile_end(pf, cast, cs, lat * width, side, up, cfg)
    if np.isfinite(end):
        return end
    if not np.isfinite(t0):  # nothing above the part: follow what is below instead
        t0, end = _profile_end(pf, cast, cs, lat * width, side, -up, cfg)
        above_floor = float(pf.center @ up) - t0 > floor + cfg.body_floor_m
        if np.isfinite(end) and above_floor:
            return end
    ends = []
    for d in (side, -side):
        t0, end = _profile_end(pf, cast, cs, lat * height, vertical, d, cfg)
        if t0 <= 0.5 * width + cfg.body_side_reach_m:
            ends.append(end)
    return float(min(ends)) if ends else np.inf


def estimate_cavity(pf: PartFrame, cast: callable, bounds: np.ndarray, frame: Frame | None,  # type: ignore[valid-type]
                    depth: np.ndarray | None, cfg: CavityConfig) -> tuple[float, str, dict[str, float]]:
    """(d_in, which bound set it, all four bounds)."""
    terms = {"hit": d_hit(pf, cast, cfg), "image": d_image(pf, frame, depth, cfg), "mesh": d_mesh(pf, bounds),
             "body": d_body(pf, cast, cfg, floor=float(bounds[0][2]))}
    src = min(terms, key=terms.get)
    d = terms[src]
    if not np.isfinite(d) or d <= 0.02:
        return cfg.default_depth_m, "default", terms
    if d > cfg.max_depth_m:
        # the nearest bound lies past any furniture's depth: the rays left the part's own body (its back
        # was never scanned) and met the room wall or a unit across the room, which bound nothing; a
        # carcass that deep stood in the room in front of that unit and jammed its doors
        return cfg.default_depth_m, "beyond_max", terms
    return float(d), src, terms


def _box(lo: np.ndarray, hi: np.ndarray, pf: PartFrame, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A closed box [lo, hi] in the part frame (u, v, n) placed at ``origin`` (8 vertices, 12 faces)."""
    c = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
    local = lo + c * (hi - lo)
    R = np.stack([pf.u, pf.v, pf.n], 1)
    verts = origin + local @ R.T
    faces = np.array([[0, 1, 2], [1, 3, 2], [4, 6, 5], [5, 6, 7], [0, 4, 1], [1, 4, 5],
                      [2, 3, 6], [3, 7, 6], [0, 2, 4], [2, 6, 4], [1, 5, 3], [3, 5, 7]])
    nrm = triangle_cross(verts, faces)
    out = (nrm * (verts[faces].mean(1) - verts.mean(0))).sum(1) < 0  # make every face point away from the centre
    faces[out] = faces[out][:, ::-1]
    return verts, faces


def _merge(boxes: list[tuple[np.ndarray, np.ndarray]], color: int) -> TriMesh:
    v, f = concat_meshes(boxes)
    return TriMesh(v, f, np.full((len(v), 3), color, np.uint8))


def wall_thickness(pf: PartFrame, cfg: CavityConfig) -> float:
    return max(cfg.min_wall_m, cfg.wall_factor * min(pf.su, pf.sv))


def level_frame(pf: PartFrame, within_deg: float, up: np.ndarray = UP) -> tuple[PartFrame, float]:
    """The part frame turned so that its normal is exactly horizontal (or vertical) when it is within
    ``within_deg`` of it, about the axis that moves it least, and ``reach``: how far behind the centre
    (along the front's own normal) the turned outline's corners lie at most; a carcass starting
    ``(gap + reach) / cos`` deep along the new normal (``cos`` between the two normals) stays ``gap`` behind
    the front's back face everywhere. Fronts further off (a sloped panel) keep their frame."""
    up = np.asarray(up, float) / np.linalg.norm(up)
    n = np.asarray(pf.n, float)
    c = float(n @ up)
    sin_lim = np.sin(np.radians(within_deg))
    if abs(c) <= sin_lim:
        target = n - c * up
    elif np.sqrt(max(0.0, 1.0 - c * c)) <= sin_lim:
        target = np.sign(c) * up
    else:
        return pf, 0.0
    target = target / np.linalg.norm(target)
    k = np.cross(n, target)
    s = float(np.linalg.norm(k))
    if s < 1e-12:
        return pf, 0.0
    k /= s
    cos = float(n @ target)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    R = np.eye(3) + s * K + (1 - cos) * (K @ K)
    u, v = R @ pf.u, R @ pf.v
    reach = 0.5 * pf.su * abs(float(u @ n)) + 0.5 * pf.sv * abs(float(v @ n))
    return PartFrame(pf.center, u, v, target, pf.su, pf.sv, pf.thickness), reach


def base_mesh(pf: PartFrame, depth: float, cfg: CavityConfig, gap: float = 0.002) -> TriMesh:
    """Open-front box behind the front: back wall and four side walls with real thickness, built level
    (``level_frame``) so that what is put on its floor stays in."""
    o, n = pf.back, pf.n
    pf, reach = level_frame(pf, cfg.level_within_deg)
    w = wall_thickness(pf, cfg)
    hu, hv = pf.su / 2, pf.sv / 2
    c0 = (gap + reach) / float(n @ pf.n)
    c1 = max(gap + depth, c0 + 2 * w)
    boxes = [
        _box(np.array([-hu, -hv, c1 - w]), np.array([hu, hv, c1]), pf, o),
        _box(np.array([-hu, -hv, c0]), np.array([-hu + w, hv, c1 - w]), pf, o),
        _box(np.array([hu - w, -hv, c0]), np.array([hu, hv, c1 - w]), pf, o),
        _box(np.array([-hu + w, -hv, c0]), np.array([hu - w, -hv + w, c1 - w]), pf, o),
        _box(np.array([-hu + w, hv - w, c0]), np.array([hu - w, hv, c1 - w]), pf, o),
    ]
    return _merge(boxes, 170)


def inner_box_mesh(pf: PartFrame, depth: float, cfg: CavityConfig, up: np.ndarray, gap: float = 0.004) -> TriMesh:
    """A drawer's open-top box behind its front (moves with it): bottom, back and two sides."""
    w = wall_thickness(pf, cfg)
    # the in-plane axis closest to 'up' is the drawer's vertical
    vert_is_v = abs(np.dot(pf.v, up)) >= abs(np.dot(pf.u, up))
    hu = pf.su / 2 - w - gap
    hv = pf.sv / 2 - w - gap
    d = max(0.02, depth - 2 * w - 2 * gap)
    c0, c1 = gap, gap + d
    o = pf.back
    t = max(0.004, w * 0.6)
    sgn = np.sign(np.dot(pf.v if vert_is_v else pf.u, up)) or 1.0
    if vert_is_v:
        bottom = (np.array([-hu, -hv, c0]), np.array([hu, -hv + t, c1])) if sgn > 0 else (np.array([-hu, hv - t, c0]), np.array([hu, hv, c1]))
        h = 0.7 * 2 * hv
        zlo, zhi = (-hv, -hv + h) if sgn > 0 else (hv - h, hv)
        walls = [(np.array([-hu, zlo, c1 - t]), np.array([hu, zhi, c1])),
                 (np.array([-hu, zlo, c0]), np.array([-hu + t, zhi, c1 - t])),
                 (np.array([hu - t, zlo, c0]), np.array([hu, zhi, c1 - t]))]
    else:
        bottom = (np.array([-hu, -hv, c0]), np.array([-hu + t, hv, c1])) if sgn > 0 else (np.array([hu - t, -hv, c0]), np.array([hu, hv, c1]))
        h = 0.7 * 2 * hu
        zlo, zhi = (-hu, -hu + h) if sgn > 0 else (hu - h, hu)
        walls = [(np.array([zlo, -hv, c1 - t]), np.array([zhi, hv, c1])),
                 (np.array([zlo, -hv, c0]), np.array([zhi, -hv + t, c1 - t])),
                 (np.array([zlo, hv - t, c0]), np.array([zhi, hv, c1 - t]))]
    return _merge([_box(lo, hi, pf, o) for lo, hi in [bottom, *walls]], 150)
