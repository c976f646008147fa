"""Colliders that keep clear of each other: no overlap at rest, and nothing static in a part's path.

A scan's background, the generated carcasses and the parts' hulls are built independently, so they
overlap where a front meets its frame, where two estimated carcasses meet at an angle, and where a
slab of background spans the gap around a front. Engines then start with hundreds of contacts and a
part jams before it moves. Here every collider is made to keep ``margin`` away from the regions it
must leave free:

- an ``Obstacle`` is a convex region (vertices, outward face normals): one part piece at rest, the
  hull of a piece at two consecutive poses along its joint (``sweep_obstacles``: its swept volume,
  in pieces), a carcass's solid hull (other carcasses keep out of it) or its cavity
  (``cavity_obstacle``: the background keeps out of it);
- ``gap`` is a separating-axis lower bound of the distance between a convex piece and an obstacle
  (face normals of both; edge-edge axes are left out, so a reported overlap may be a near miss: the
  test errs towards carving, never towards an overlap);
- ``keep_clear`` cuts a convex piece by the one half-space, among those axes, that keeps most of
  its volume while clearing the obstacle by ``margin`` (the result stays convex; a piece left
  thinner than ``MIN_PIECE_M`` is dropped);
- ``territory_plane`` / ``keep_side``: two neighbours that meet split the space between their
  fronts; ``separate_at_rest``: of two part pieces overlapping at rest the smaller yields;
  ``clear_paths``: where a part's path meets another part, the cheaper of the two cuts;
- ``face_conflicts`` / ``carve_faces`` flag the triangles of a static mesh that come within
  ``margin`` of an obstacle (splitting big ones so only what is in the way goes).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial import ConvexHull, HalfspaceIntersection
from scipy.spatial import QhullError

from ..data.parts import Articulation
from .collision import ConvexPiece

MIN_PIECE_M = 0.001
"""A clipped piece thinner than this (m) along any of its axes is dropped (a sliver collides with nothing useful)."""

MAX_SWEEP_STEPS = 64


@dataclass
class Obstacle:
    """A convex region other colliders keep ``margin + grow`` away from."""

    vertices: np.ndarray  # (V,3) hull vertices
    normals: np.ndarray  # (F,3) unit outward face normals (no duplicates)
    lo: np.ndarray  # AABB
    hi: np.ndarray
    grow: float  # extra distance to keep (the chord error of a swept arc)
    owner: str  # object id of the part or carcass it stands for
    kind: str  # "rest", "sweep", "carcass", "cavity"

    @property
    def vmin(self) -> np.ndarray:
        """min over vertices of n . v for each normal."""
        return (self.vertices @ self.normals.T).min(0)

    @property
    def vmax(self) -> np.ndarray:
        return (self.vertices @ self.normals.T).max(0)


def _hull(points: np.ndarray) -> ConvexHull | None:
    pts = np.asarray(points, float)
    if len(pts) < 4:
        return None
    try:
        return ConvexHull(pts)
    except QhullError:
        try:
            return ConvexHull(pts, qhull_options="QJ")
        except QhullError:
            return None


def unique_axes(normals: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Unit directions of ``normals`` with duplicates and opposites removed (SAT tests both sides)."""
    n = np.asarray(normals, float)
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    first = np.argmax(np.abs(n) > 1e-9, axis=1)
    n = n * np.where(n[np.arange(len(n)), first] < 0, -1.0, 1.0)[:, None]
    _, idx = np.unique(np.round(n / tol).astype(np.int64), axis=0, return_index=True)
    return n[np.sort(idx)]


def hull_obstacle(points: np.ndarray, owner: str, kind: str, grow: float = 0.0) -> Obstacle | None:
    """The convex hull of ``points`` as an obstacle (None for fewer than 4 independent points)."""
    h = _hull(points)
    if h is None:
        return None
    v = h.points[h.vertices]
    return Obstacle(v, unique_axes(h.equations[:, :3]), v.min(0), v.max(0), float(grow), owner, kind)


def piece_axes(piece: ConvexPiece) -> np.ndarray:
    """Face-normal directions of a convex piece (3 for a box; computed once per piece)."""
    return piece.axes


class ObstacleSet:
    """Obstacles with their bounding boxes in arrays, so a piece tests only those near it."""

    def __init__(self, obstacles: Sequence[Obstacle]) -> None:
        self.items = list(obstacles)
        self.lo = np.array([o.lo - o.grow for o in self.items]).reshape(-1, 3)
        self.hi = np.array([o.hi + o.grow for o in self.items]).reshape(-1, 3)

    def near(self, lo: np.ndarray, hi: np.ndarray, pad: float) -> list[Obstacle]:
        """Obstacles whose (grown) box comes within ``pad`` of [lo, hi], in their order."""
        if not self.items:
            return []
        ok = np.all(self.lo <= hi + pad, axis=1) & np.all(self.hi >= lo - pad, axis=1)
        return [self.items[i] for i in np.flatnonzero(ok)]


def sweep_obstacles(pieces: Sequence[ConvexPiece], art: Articulation, owner: str, margin: float) -> list[Obstacle]:
    """The space ``pieces`` pass through from ``art.lower`` to ``art.upper``, as convex obstacles.

    Prismatic: each piece's hull at both ends (a translated convex set sweeps exactly that hull).
    Revolute: each piece's hull at consecutive angles, one obstacle per step, with steps small
    enough that the arc leaves the chord by at most ``margin / 2`` (added to the obstacle's growth).
    """
    out: list[Obstacle] = []
    span = art.upper - art.lower
    o, a = np.asarray(art.origin, float), np.asarray(art.axis, float)
    err = max(margin / 2, 1e-4)
    for p in pieces:
        if art.joint_type != "revolute":
            qs = np.array([art.lower, art.upper])
            chord = 0.0
        else:
            rel = p.vertices - o
            r = float(np.linalg.norm(rel - np.outer(rel @ a, a), axis=1).max())
            step = 2 * math.acos(1 - err / r) if r > err else span
            n = int(min(MAX_SWEEP_STEPS, max(1, math.ceil(span / step))))
            qs = np.linspace(art.lower, art.upper, n + 1)
            chord = r * (1 - math.cos(span / n / 2))
        poses = [art.move(p.vertices, q) for q in qs]
        for k in range(len(qs) - 1):
            ob = hull_obstacle(np.vstack([poses[k], poses[k + 1]]), owner, "sweep", grow=chord)
            if ob is not None:
                out.append(ob)
    return out


def cavity_obstacle(walls: Sequence[ConvexPiece], owner: str) -> Obstacle | None:
    """The free space inside a carcass: the hull of its walls, each face moved inwards by the walls'
    thickness (the median of their thinnest extents). What stands there blocks the cavity; what only
    touches the walls from outside meets a static body it never collides with."""
    if not walls:
        return None
    h = _hull(np.vstack([p.vertices for p in walls]))
    if h is None:
        return None
    t = float(np.median([np.ptp(p.vertices @ p.axes.T, axis=0).min() for p in walls]))
    eq = h.equations.copy()
    eq[:, 3] += t  # n . x + d <= -t: t inside every face
    centre = h.points[h.vertices].mean(0)
    if np.any(eq[:, :3] @ centre + eq[:, 3] >= 0):
        return None  # thinner than its walls: no cavity
    try:
        pts = HalfspaceIntersection(eq, centre).intersections
    except QhullError:
        return None
    return hull_obstacle(pts, owner, "cavity")


def gap(vertices: np.ndarray, axes: np.ndarray, ob: Obstacle) -> tuple[float, np.ndarray, float]:
    """(separation, axis, side) of a convex point set and an obstacle along the best tested axis.

    ``side`` +1: the set lies on the +axis side of the obstacle. Separation < 0 means overlap along
    every tested axis (a lower bound of the true distance when positive)."""
    A = np.vstack([axes, ob.normals])
    pp = vertices @ A.T
    oo = ob.vertices @ A.T
    below = oo.min(0) - pp.max(0)  # set below the obstacle
    above = pp.min(0) - oo.max(0)
    g = np.maximum(below, above)
    k = int(np.argmax(g))
    return float(g[k]), A[k], 1.0 if above[k] >= below[k] else -1.0


def batched_gap(points: np.ndarray, axes: np.ndarray, ob: Obstacle) -> np.ndarray:
    """``gap`` for many small convex sets at once: points (m,K,3), their own axes (m,A,3) -> (m,)."""
    po = points @ ob.normals.T  # (m,K,F)
    g1 = np.maximum(ob.vmin[None] - po.max(1), po.min(1) - ob.vmax[None]).max(1)
    pa = np.einsum("mkj,maj->mka", points, axes)
    oa = np.einsum("vj,maj->mva", ob.vertices, axes)
    g2 = np.maximum(oa.min(1) - pa.max(1), pa.min(1) - oa.max(1)).max(1)
    return np.maximum(g1, g2)


def clip_halfspace(vertices: np.ndarray, a: np.ndarray, t: float) -> np.ndarray | None:
    """Vertices of conv(vertices) intersected with {x : a . x <= t} (None if empty).

    Every segment between a vertex inside and one outside is cut at the plane: the cuts of the
    polytope's edges are among them, the others lie inside, so the hull of the result is exact."""
    s = vertices @ a - t
    inside = s <= 1e-12
    if inside.all():
        return vertices
    if not inside.any():
        return None
    i, j = np.nonzero(inside[:, None] & ~inside[None, :])
    w = s[i] / (s[i] - s[j])
    cut = vertices[i] + w[:, None] * (vertices[j] - vertices[i])
    return np.vstack([vertices[inside], cut])


def _piece(points: np.ndarray, source: str) -> ConvexPiece | None:
    """A closed convex piece (outward faces) from ``points``; None when thinner than ``MIN_PIECE_M``."""
    h = _hull(points)
    if h is None:
        return None
    used = h.vertices
    v = h.points[used]
    c = v - v.mean(0)
    if np.ptp(c @ np.linalg.svd(c, full_matrices=False)[2].T, axis=0).min() < MIN_PIECE_M:
        return None
    remap = np.full(len(h.points), -1)
    remap[used] = np.arange(len(used))
    f = remap[h.simplices]
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    flip = np.sum(n * h.equations[:, :3], axis=1) < 0  # qhull's facet normals point outward
    f[flip] = f[flip][:, ::-1]
    return ConvexPiece(v, f, source)


def _volume(points: np.ndarray) -> float:
    h = _hull(points)
    return float(h.volume) if h is not None else 0.0


def clip_clear(piece: ConvexPiece, ob: Obstacle, margin: float, candidates: int = 2) -> ConvexPiece | None:
    """``piece`` cut back by one plane so that it clears ``ob`` by ``margin + ob.grow``: of the tested
    axes (both shapes' face normals), the cut that keeps the most volume (the ``candidates`` best by
    the share of the piece's extent they keep are cut exactly). None if nothing is left."""
    need = margin + ob.grow
    v = piece.vertices
    A = np.vstack([piece_axes(piece), ob.normals])
    pp, oo = v @ A.T, ob.vertices @ A.T
    pmin, pmax, omin, omax = pp.min(0), pp.max(0), oo.min(0), oo.max(0)
    span = np.maximum(pmax - pmin, 1e-12)
    # side 1 keeps a . x <= omin - need, side 2 keeps a . x >= omax + need
    keep1 = np.clip((omin - need - pmin) / span, 0, 1)
    keep2 = np.clip((pmax - (omax + need)) / span, 0, 1)
    opts = sorted([(keep1[k], k, 1) for k in range(len(A))] + [(keep2[k], k, 2) for k in range(len(A))], key=lambda o: -o[0])
    best: tuple[float, np.ndarray | None, int] = (-1.0, None, -1)
    for frac, k, side in opts[:candidates]:
        if frac <= 0:
            continue
        pts = clip_halfspace(v, A[k], omin[k] - need) if side == 1 else clip_halfspace(v, -A[k], -(omax[k] + need))
        if pts is not None and (vol := _volume(pts)) > best[0]:
            best = (vol, pts, k)
    if best[1] is None:
        return None
    if piece.box is not None:  # a box cut across (nearly) one of its own axes stays a box, if it still clears
        _, R, _ = piece.box_frame()
        if np.max(np.abs(R.T @ A[best[2]])) > 1 - 1e-6:
            box = _box_piece(best[1], R, piece.source)
            if box is None or gap(box.vertices, R.T, ob)[0] >= need - 1e-6:
                return box
    return _piece(best[1], piece.source)


def _box_piece(points: np.ndarray, R: np.ndarray, source: str) -> ConvexPiece | None:
    """The box with axes ``R`` (columns) bounding ``points``; None when thinner than ``MIN_PIECE_M``."""
    local = points @ R
    lo, hi = local.min(0), local.max(0)
    if np.min(hi - lo) < MIN_PIECE_M:
        return None
    unit = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
    corners = (lo + unit * (hi - lo)) @ R.T
    hull = trimesh.Trimesh(corners, process=False).convex_hull
    box = np.concatenate([R @ ((lo + hi) / 2), R.reshape(9), hi - lo])
    return ConvexPiece(np.asarray(hull.vertices), np.asarray(hull.faces), source, box)


def _overlaps(lo: np.ndarray, hi: np.ndarray, ob: Obstacle, pad: float) -> bool:
    return bool(np.all(lo <= ob.hi + pad) and np.all(hi >= ob.lo - pad))


@dataclass
class ClearStats:
    """What keeping clear did: pieces cut, dropped, and conflicts left (a cut too large to make)."""

    cut: int = 0
    dropped: int = 0
    left: int = 0


def keep_clear(pieces: Sequence[ConvexPiece], obstacles: Sequence[Obstacle] | ObstacleSet, margin: float
               ) -> tuple[list[ConvexPiece], ClearStats]:
    """Cut each piece back until it clears every obstacle by ``margin`` (see ``clip_clear``).

    One pass suffices: a half-space cut only shrinks a piece, so one that cleared an earlier
    obstacle stays clear of it."""
    obs = obstacles if isinstance(obstacles, ObstacleSet) else ObstacleSet(obstacles)
    stats = ClearStats()
    out: list[ConvexPiece] = []
    for piece in pieces:
        cur: ConvexPiece | None = piece
        for ob in obs.near(piece.vertices.min(0), piece.vertices.max(0), margin):
            need = margin + ob.grow
            v = cur.vertices
            if not _overlaps(v.min(0), v.max(0), ob, need) or gap(v, piece_axes(cur), ob)[0] >= need - 1e-9:
                continue
            cur = clip_clear(cur, ob, margin)
            if cur is None:
                break
        if cur is None:
            stats.dropped += 1
        else:
            stats.cut += cur is not piece
            out.append(cur)
    return out, stats


class BoxIndex:
    """Boxes (AABBs of faces or slabs) sorted by centre x, so an obstacle only tests the boxes in its
    x-window (a scene is long in x or y, an obstacle short). Boxes wider than ``wide`` in x are always tested."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray, wide: float = 0.5) -> None:
        self.lo, self.hi = lo, hi
        w = hi[:, 0] - lo[:, 0]
        self.big = np.flatnonzero(w > wide)
        small = np.flatnonzero(w <= wide)
        cx = (lo[small, 0] + hi[small, 0]) / 2
        order = np.argsort(cx, kind="stable")
        self.cx, self.ids = cx[order], small[order]
        self.half = float(w[small].max()) / 2 if len(small) else 0.0

    def near(self, lo: np.ndarray, hi: np.ndarray, pad: float) -> np.ndarray:
        """Ids of boxes whose AABB comes within ``pad`` of [lo, hi]."""
        a = np.searchsorted(self.cx, lo[0] - pad - self.half, "left")
        b = np.searchsorted(self.cx, hi[0] + pad + self.half, "right")
        idx = np.concatenate([self.ids[a:b], self.big]) if len(self.big) else self.ids[a:b]
        keep = np.all(self.lo[idx] <= hi + pad, axis=1) & np.all(self.hi[idx] >= lo - pad, axis=1)
        return idx[keep]


def face_conflicts(vertices: np.ndarray, faces: np.ndarray, obstacles: Sequence[Obstacle], margin: float,
                   chunk: int = 20000) -> np.ndarray:
    """Bool per face: the triangle comes within ``margin`` (+ the obstacle's growth) of an obstacle."""
    tri = np.asarray(vertices, float)[np.asarray(faces, np.int64)]
    out = np.zeros(len(tri), bool)
    if not len(tri) or not obstacles:
        return out
    index = BoxIndex(tri.min(1), tri.max(1))
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(ln > 1e-15, nrm / np.maximum(ln, 1e-300), np.array([0.0, 0.0, 1.0]))
    for ob in obstacles:
        need = margin + ob.grow
        idx = index.near(ob.lo, ob.hi, need)
        idx = idx[~out[idx]]
        for s in range(0, len(idx), chunk):
            ids = idx[s : s + chunk]
            g = batched_gap(tri[ids], nrm[ids][:, None, :], ob)
            out[ids[g < need]] = True
    return out


def box_conflicts(corners: np.ndarray, axes: np.ndarray, obstacles: Sequence[Obstacle], margin: float) -> np.ndarray:
    """Bool per box (corners (m,8,3), axes (m,3,3)): within ``margin`` of an obstacle."""
    out = np.zeros(len(corners), bool)
    if not len(corners) or not obstacles:
        return out
    index = BoxIndex(corners.min(1), corners.max(1))
    for ob in obstacles:
        need = margin + ob.grow
        idx = index.near(ob.lo, ob.hi, need)
        idx = idx[~out[idx]]
        if len(idx):
            out[idx[batched_gap(corners[idx], axes[idx], ob) < need]] = True
    return out


BACK_TO_BACK_GAP_M = 0.1
"""Fronts turned more than 135 degrees are back to back (the bisector parts them) only this far apart along
it (m): a carcass's depth; nearer, they are neighbours in one plane with one normal estimated flipped."""


def territory_plane(front_a: np.ndarray, normal_a: np.ndarray, front_b: np.ndarray, normal_b: np.ndarray,
                    parallel_deg: float = 5.0, axes: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """A plane between two neighbouring objects: (m, c) with A's front on the side m . x < c.

    Fronts turned against each other (a corner, or two fronts whose estimated normals differ) share
    the bisector of their planes, through the line where the planes meet, when it has each front on
    its own side (fronts turned more than 135 degrees only when one lies wholly behind the other: back
    to back, ``BACK_TO_BACK_GAP_M`` apart; side by side, one normal was estimated flipped); otherwise (coplanar fronts side by side or stacked) the plane lies across one
    direction in the fronts' plane, in the middle of the gap between them along it. ``axes``: candidate
    directions (the fronts' box axes); the one along which the fronts lie furthest apart is used (a
    tall door beside a drawer high up: across the row, not along the line between their centres).
    Without ``axes``, the direction from A's centre (mean point) to B's."""
    na = np.asarray(normal_a, float) / np.linalg.norm(normal_a)
    nb = np.asarray(normal_b, float) / np.linalg.norm(normal_b)
    ca, cb = front_a.mean(0), front_b.mean(0)
    d = na - nb
    if np.linalg.norm(d) > 2 * np.sin(np.radians(parallel_deg) / 2):
        m = d / np.linalg.norm(d)
        c = float(na @ ca - nb @ cb) / float(np.linalg.norm(d))
        if m @ ca > c:
            m, c = -m, -c
        apart = np.mean(front_a @ m < c) >= 0.9 and np.mean(front_b @ m > c) >= 0.9
        if apart and float(na @ nb) < -np.cos(np.radians(45.0)):
            # turned more than 135 degrees: back to back (one behind the other along m), or one normal
            # estimated flipped on coplanar fronts, whose bisector then runs through both
            apart = float((front_b @ m).min()) - float((front_a @ m).max()) >= BACK_TO_BACK_GAP_M
        if apart:
            return m, c
    mean_n = na + (nb if float(na @ nb) >= 0 else -nb)  # a flipped normal still names the same plane
    mean_n = mean_n / np.linalg.norm(mean_n) if np.linalg.norm(mean_n) > 1e-9 else na
    if axes is not None:
        cand = np.asarray(axes, float).reshape(-1, 3)
        cand = cand - (cand @ mean_n)[:, None] * mean_n  # in the fronts' plane
        ln = np.linalg.norm(cand, axis=1)
        cand = cand[ln > 0.5] / ln[ln > 0.5, None]  # axes along the normal drop out
        if len(cand):
            cand = cand * np.where(cand @ (cb - ca) < 0, -1.0, 1.0)[:, None]  # from A to B
            gaps = (front_b @ cand.T).min(0) - (front_a @ cand.T).max(0)
            m = cand[int(np.argmax(gaps))]
            return m, float((np.max(front_a @ m) + np.min(front_b @ m)) / 2)
    m = (cb - ca) - ((cb - ca) @ mean_n) * mean_n
    if np.linalg.norm(m) < 1e-9:
        m = cb - ca
    m = m / max(np.linalg.norm(m), 1e-12)
    return m, float((np.max(front_a @ m) + np.min(front_b @ m)) / 2)


def keep_side(pieces: Sequence[ConvexPiece], m: np.ndarray, c: float, max_loss: float | None = None) -> tuple[list[ConvexPiece], int]:
    """``pieces`` cut to the half-space m . x <= c (a piece left thinner than ``MIN_PIECE_M`` is dropped);
    returns them and how many were cut or dropped. ``max_loss``: a piece that would lose more than this
    share of its volume is left whole (for a later, cheaper cut elsewhere)."""
    out, changed = [], 0
    for p in pieces:
        if float((p.vertices @ m).max()) <= c:
            out.append(p)
            continue
        pts = clip_halfspace(p.vertices, m, c)
        new = _piece(pts, p.source) if pts is not None else None
        if max_loss is not None and (0.0 if new is None else new.volume) < (1 - max_loss) * p.volume:
            out.append(p)
            continue
        changed += 1
        if new is not None:
            out.append(new)
    return out, changed


def separate_at_rest(groups: Sequence[Sequence[ConvexPiece]], margin: float) -> tuple[list[list[ConvexPiece]], ClearStats]:
    """Pieces of different groups (parts) that overlap at rest: the smaller piece is cut back to clear
    the larger by ``margin`` (a fragment of one front lying on its neighbour yields, not the front)."""
    out = [list(g) for g in groups]
    stats = ClearStats()
    flat = [(gi, pi) for gi, g in enumerate(out) for pi in range(len(g))]
    if len(flat) < 2:
        return out, stats
    lo = np.array([out[g][i].vertices.min(0) for g, i in flat])
    hi = np.array([out[g][i].vertices.max(0) for g, i in flat])
    owner = np.array([g for g, _ in flat])
    near = np.all(lo[:, None] <= hi[None] + margin, axis=2) & np.all(hi[:, None] >= lo[None] - margin, axis=2)
    near &= owner[:, None] != owner[None]
    cut: set[tuple[int, int]] = set()
    dropped: set[tuple[int, int]] = set()
    for a, b in zip(*np.nonzero(np.triu(near, 1))):
        (ga, ia), (gb, ib) = flat[a], flat[b]
        pa, pb = out[ga][ia], out[gb][ib]
        if pa is None or pb is None:
            continue
        (gs, is_, ps), (gl, il, pl) = sorted([(ga, ia, pa), (gb, ib, pb)], key=lambda t: t[2].volume)
        ob = hull_obstacle(pl.vertices, str(gl), "rest")
        if ob is None or gap(ps.vertices, piece_axes(ps), ob)[0] >= margin - 1e-9:
            continue
        new = clip_clear(ps, ob, margin)
        out[gs][is_] = new  # type: ignore[call-overload]
        (cut if new is not None else dropped).add((gs, is_))
    stats.cut = len(cut - dropped)
    stats.dropped = len(dropped)
    return [[p for p in g if p is not None] for g in out], stats


def reverse(art: Articulation) -> Articulation:
    """The motion of the world seen from the moving part (same joint line, range negated)."""
    return art.model_copy(update={"lower": -art.upper, "upper": -art.lower})


def _loss(piece: ConvexPiece, new: ConvexPiece | None) -> float:
    return piece.volume - (new.volume if new is not None else 0.0)


def clear_paths(parts: Sequence[Sequence[ConvexPiece]], arts: Sequence[Articulation], margin: float,
                max_fraction: float, fragment: float = 0.02) -> tuple[list[list[ConvexPiece]], list[list[Obstacle]], ClearStats]:
    """Each part driven alone must not sweep through another part at rest.

    For a moving piece p whose path meets a resting piece q, either q is cut out of p's path or p is
    cut clear of q's reverse path (q as the moving part sees it), whichever removes less volume. A
    cut is refused when it removes more than ``max_fraction`` of the piece (unless the piece is a
    fragment: under ``fragment`` of its part's volume): then the conflict is left (a joint limit).
    Returns the pieces, each part's swept volume and counts. A piece cut as the resting one after its
    own path was traced keeps that path: it contains the smaller piece's, so carving around it is safe."""
    out = [list(g) for g in parts]
    total = [sum(p.volume for p in g) for g in out]
    stats = ClearStats()
    changed: set[tuple[int, int]] = set()
    dropped: set[tuple[int, int]] = set()

    def allowed(gi: int, piece: ConvexPiece, new: ConvexPiece | None) -> bool:
        v = piece.volume
        return _loss(piece, new) <= max_fraction * v + 1e-12 or v <= fragment * total[gi]

    flat = [(g, i) for g in range(len(out)) for i in range(len(out[g]))]
    lo_all = np.array([out[g][i].vertices.min(0) for g, i in flat]).reshape(-1, 3)
    hi_all = np.array([out[g][i].vertices.max(0) for g, i in flat]).reshape(-1, 3)
    sweeps: list[list[list[Obstacle]]] = [[[] for _ in g] for g in out]
    for ga, art in enumerate(arts):
        for ia in range(len(out[ga])):
            p = out[ga][ia]
            sweep = sweep_obstacles([p], art, str(ga), margin) if p is not None else []
            sweeps[ga][ia] = sweep
            if not sweep:
                continue
            lo, hi = np.min([o.lo for o in sweep], 0), np.max([o.hi for o in sweep], 0)
            near = np.all(lo_all <= hi + 2 * margin, axis=1) & np.all(hi_all >= lo - 2 * margin, axis=1)
            for k in np.flatnonzero(near):  # boxes only shrink: candidates found once stay a superset
                gb, ib = flat[k]
                q = out[gb][ib]
                if gb == ga or q is None or p is None:
                    continue
                q_cut, st = keep_clear([q], sweep, margin)
                if not (st.cut or st.dropped):
                    continue
                q_new = q_cut[0] if q_cut else None
                p_cut, _ = keep_clear([p], sweep_obstacles([q], reverse(art), str(gb), margin), margin)
                p_new = p_cut[0] if p_cut else None
                options = [o for o in [(gb, ib, q, q_new), (ga, ia, p, p_new)] if allowed(o[0], o[2], o[3])]
                if not options:
                    stats.left += 1
                    continue
                g, i, _, new = min(options, key=lambda o: _loss(o[2], o[3]))
                out[g][i] = new  # type: ignore[call-overload]
                (changed if new is not None else dropped).add((g, i))
                if (g, i) == (ga, ia):
                    p = new
                    sweep = sweep_obstacles([p], art, str(ga), margin) if p is not None else []
                    sweeps[ga][ia] = sweep
    stats.cut = len(changed - dropped)
    stats.dropped = len(dropped)
    final = [[p for p in g if p is not None] for g in out]
    paths = [[ob for i, p in enumerate(g) if p is not None for ob in sweeps[k][i]] for k, g in enumerate(out)]
    return final, paths, stats


def _split4(tri: np.ndarray) -> np.ndarray:
    """Each triangle (m,3,3) split at its edge midpoints into 4 (4m,3,3)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
    return np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1), np.stack([ab, bc, ca], 1)], 1).reshape(-1, 3, 3)


def carve_faces(vertices: np.ndarray, faces: np.ndarray, obstacles: Sequence[Obstacle], margin: float,
                min_edge: float, max_levels: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The static surface less what lies within ``margin`` of an obstacle.

    Returns (bool per face: kept whole, fragments (k,3,3)): a face in conflict whose longest edge
    exceeds ``min_edge`` is split in 4 and its pieces tested again (a wall made of two big triangles
    loses only what is near the carcass in front of it, not the whole wall)."""
    conflict = face_conflicts(vertices, faces, obstacles, margin)
    tri = np.asarray(vertices, float)[np.asarray(faces, np.int64)[conflict]]
    kept: list[np.ndarray] = []
    for _ in range(max_levels):
        edge = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(1) if len(tri) else np.zeros(0)
        tri = _split4(tri[edge > min_edge])
        if not len(tri):
            break
        flat = tri.reshape(-1, 3)
        bad = face_conflicts(flat, np.arange(len(flat)).reshape(-1, 3), obstacles, margin)
        kept.append(tri[~bad])
        tri = tri[bad]
    frags = np.concatenate(kept) if kept else np.zeros((0, 3, 3))
    return ~conflict, frags
