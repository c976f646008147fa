"""What the check aims at, read from the manifest (``scene.json``): each object's front, its cavity, and
which exported joint moves it.

Front: the part's box (OBB) at q = 0; ``n`` is the manifest's ``front_normal`` (into the cavity), the
front's thickness is the OBB side most aligned with ``n``, its outer face is ``center - n t / 2``.
Cavity: the box behind the front's back face, as wide and tall as the front, ``cavity_depth`` deep.
A drawer's cavity (an object with an inner box) moves with the part; a door's stays in place.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..data.parts import Articulation, InteractiveObject, InteractiveScene

UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Front:
    object_id: str
    articulation: Articulation
    center: np.ndarray
    n: np.ndarray  # unit, into the cavity
    u: np.ndarray
    v: np.ndarray
    su: float
    sv: float
    thickness: float
    cavity_depth: float | None
    moving_cavity: bool

    @property
    def outer(self) -> np.ndarray:
        """Centre of the outer face (the side a robot sees)."""
        return self.center - self.n * self.thickness / 2

    @property
    def back(self) -> np.ndarray:
        return self.center + self.n * self.thickness / 2

    @property
    def goal(self) -> float:
        """The limit the check drives to: the upper one, or the lower one when only that opens."""
        a = self.articulation
        return a.upper if a.upper > 0 else a.lower


def front_of(obj: InteractiveObject) -> Front:
    R = np.asarray(obj.obb.axes, float)  # rows u1, u2, u3
    ext = np.asarray(obj.obb.extents, float)
    n = np.asarray(obj.front_normal, float)
    n = n / np.linalg.norm(n)
    k = int(np.argmax(np.abs(R @ n)))
    (i, j) = [m for m in range(3) if m != k]
    return Front(obj.object_id, obj.articulation, np.asarray(obj.obb.center, float), n, R[i], R[j], float(ext[i]),
                 float(ext[j]), float(ext[k]), obj.cavity_depth, obj.inner_mesh is not None)


def fronts(scene: InteractiveScene) -> list[Front]:
    return [front_of(o) for o in scene.objects]


# ------------------------------------------------------------------ probes
@dataclass(frozen=True)
class CavityBox:
    """A box in the front's frame: ``center`` and axes (u, v, n) with half sizes, at joint value 0."""

    center: np.ndarray
    axes: np.ndarray  # 3x3, columns u, v, n
    half: np.ndarray

    def moved(self, art: Articulation | None, q: float) -> "CavityBox":
        if art is None or q == 0:
            return self
        T = art.transform(q)
        return CavityBox(T[:3, :3] @ self.center + T[:3, 3], T[:3, :3] @ self.axes, self.half)

    def local(self, p: np.ndarray) -> np.ndarray:
        return (np.asarray(p, float) - self.center) @ self.axes

    def contains(self, p: np.ndarray, tol: float = 1e-3) -> bool:
        return bool(np.all(np.abs(self.local(p)) <= self.half + tol))

    def corners(self) -> np.ndarray:
        s = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float) * self.half
        return self.center + s @ self.axes.T


def cavity_box(f: Front) -> CavityBox:
    """The cavity at q = 0 (None-depth fronts have none: the caller skips them)."""
    d = float(f.cavity_depth or 0.0)
    return CavityBox(f.back + f.n * d / 2, np.stack([f.u, f.v, f.n], 1), np.array([f.su / 2, f.sv / 2, d / 2]))


def probe_radius(f: Front, radius: float) -> float:
    """``radius``, shrunk to 15 % of the smallest side of a small front or cavity."""
    sides = [f.su, f.sv] + ([f.cavity_depth] if f.cavity_depth else [])
    return float(min(radius, 0.15 * min(sides)))


@dataclass(frozen=True)
class CavityProbe:
    spawn: np.ndarray  # where it is dropped from
    box: CavityBox  # at the open joint value
    radius: float
    center: np.ndarray  # the point it is first placed at, to see the space is clear (``spawn`` before lowering)


def lowered(p: np.ndarray, box: CavityBox, r: float, drop: float | None, up: np.ndarray = UP) -> np.ndarray:
    """``p`` moved straight down until its lowest point is at most ``drop`` above the box's lowest corner
    (unchanged when it already is, or with no ``drop``)."""
    if drop is None:
        return p
    bottom = float((box.corners() @ up).min())
    excess = float(np.dot(p, up)) - r - bottom - drop
    return p - up * excess if excess > 0 else p


def cavity_probe(f: Front, radius: float, margin: float = 0.01, drop: float | None = None) -> CavityProbe:
    """Where the probe is placed with the joint at its goal: a door's cavity at its centre; a drawer's in
    the middle of the part of it pulled out of the body (centre height), at least ``radius + margin``
    from its front and back. It is dropped from straight below that point, at most ``drop`` above the
    cavity's floor (``lowered``)."""
    r = probe_radius(f, radius)
    box = cavity_box(f)
    if not f.moving_cavity:
        return CavityProbe(lowered(box.center, box, r, drop), box, r, box.center)
    a = f.articulation
    d = float(f.cavity_depth or 0.0)
    out = abs(f.goal) * max(0.0, -float(np.dot(a.axis, f.n)) * np.sign(f.goal)) if a.joint_type == "prismatic" else d
    s = float(np.clip(min(out, d) / 2, r + margin, max(r + margin, d - r - margin)))
    p = a.move((f.back + f.n * s)[None], f.goal)[0]
    moved = box.moved(a, f.goal)
    return CavityProbe(lowered(p, moved, r, drop), moved, r, p)


def fell_enough(box: CavityBox, spawn: np.ndarray, end: np.ndarray, r: float, up: np.ndarray = UP) -> bool:
    """The probe came down at least half of the way from its spawn height to the cavity's lowest face
    (less its radius): it was not held up by a collider inside the cavity."""
    bottom = float((box.corners() @ up).min())
    drop = float(np.dot(spawn, up)) - (bottom + r)
    return float(np.dot(spawn - end, up)) >= 0.5 * max(drop, 0.0)


@dataclass(frozen=True)
class FrontProbe:
    start: np.ndarray
    velocity: np.ndarray
    radius: float


def front_probe(f: Front, radius: float, speed: float, gap: float = 0.05) -> FrontProbe:
    """A probe ``gap`` in front of the closed front's outer face (centre), sent along ``n`` at ``speed``."""
    r = probe_radius(f, radius)
    return FrontProbe(f.outer - f.n * (r + gap), f.n * speed, r)


def advance(f: Front, p: np.ndarray, r: float) -> float:
    """How far the probe's leading point is past the front's back face (m; <= 0: it has not got through
    the front). The back face, not the outer one: a front's box includes its handles, and a scanned
    front is an open sheet whose box ends at the panel."""
    return float(np.dot(np.asarray(p, float) - f.back, f.n) + r)


# ------------------------------------------------------------------ joints
@dataclass(frozen=True)
class JointPose:
    """A joint as the engine built it, at q = 0, in world coordinates."""

    name: str
    joint_type: str
    anchor: np.ndarray
    axis: np.ndarray


def _safe(text: str) -> str:
    """An object id as the exporters spell it in names (``export.model.safe_name``, whose package is slow
    to import)."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", text)
    return s if s and not s[0].isdigit() else f"_{s}"


def match_joints(objects: Sequence[Front], joints: Sequence[JointPose], tol_m: float = 0.01,
                 tol_cos: float = 0.999) -> dict[str, Front]:
    """``{joint name: front}``: each object to the joint of the same type whose axis agrees (within
    ~2.6 degrees) and whose anchor lies within ``tol_m`` of the articulation origin, the nearest one;
    the name decides between equals, and stands in when no joint matches the geometry (exported names
    need not follow object ids)."""
    out: dict[str, Front] = {}
    free = {j.name: j for j in joints}
    for f in objects:
        a = f.articulation
        ax, org = np.asarray(a.axis, float), np.asarray(a.origin, float)
        scored = []
        for j in free.values():
            if j.joint_type != a.joint_type or float(np.dot(j.axis, ax)) < tol_cos:
                continue
            dist = float(np.linalg.norm(j.anchor - org))
            if dist <= tol_m:
                scored.append((dist, _safe(f.object_id) not in j.name, j.name))
        if not scored:
            named = [n for n in free if n.startswith(_safe(f.object_id))]
            if len(named) == 1:
                scored.append((0.0, False, named[0]))
        if scored:
            name = min(scored)[2]
            out[name] = f
            free.pop(name)
    return out
