"""Procedural furniture with real joints: cabinets (doors, drawers, top/bottom-hinged fronts, sliding
door pairs), room doors.

Everything is built in a *wall frame*: x runs along the wall (left to right seen from the room),
+y points into the wall (away from the room), z is up, and the furniture front lies at y = 0.
``WallFrame.T`` maps it to the world. Each movable front is a :class:`PartSpec` whose joint is given
in the world frame with the scan's (closed) state at q = 0 and q in [0, upper] opening the part.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.parts import Articulation
from .builder import MeshBuilder
from .materials import GLOSSY, MATTE, METAL, WOOD

BOARD = 0.018       # carcass board thickness
FRONT = 0.019       # front slab thickness
PROUD = 0.002       # fronts sit this far in front of the carcass
GAP = 0.004         # gap between neighbouring fronts


@dataclass
class WallFrame:
    """Placement of a wall-frame origin in the world (rotation about z + translation)."""

    origin: np.ndarray
    theta: float

    @property
    def T(self) -> np.ndarray:
        c, s = np.cos(self.theta), np.sin(self.theta)
        T = np.eye(4)
        T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        T[:3, 3] = self.origin
        return T

    def shifted(self, dx: float, dy: float = 0.0) -> "WallFrame":
        R = self.T[:3, :3]
        return WallFrame(self.origin + R @ np.array([dx, dy, 0.0]), self.theta)


@dataclass
class PartSpec:
    """One movable front: GT label, joint in world, handle key, carcass key and true cavity depth."""

    key: str
    label: str
    kind: str                      # door | drawer | flap (top-hinged) | drop (bottom-hinged) | sliding | room_door
    articulation: Articulation
    parent_key: str | None
    handle_key: str | None = None
    interior_depth: float | None = None


@dataclass
class Palette:
    """Colours plus the materials the photo renderer gives fronts and carcasses (handles are metal)."""

    front: tuple[int, int, int]
    carcass: tuple[int, int, int]
    handle: tuple[int, int, int]
    material: int = MATTE
    carcass_material: int = MATTE


PALETTES = [
    Palette((235, 232, 225), (225, 222, 214), (70, 70, 75), GLOSSY),
    Palette((120, 85, 55), (105, 75, 50), (200, 200, 205), WOOD, WOOD),
    Palette((60, 90, 120), (230, 228, 222), (210, 210, 212), GLOSSY),
    Palette((170, 140, 100), (160, 130, 95), (40, 40, 42), WOOD, WOOD),
    Palette((90, 110, 85), (220, 215, 205), (190, 160, 80), MATTE),
    Palette((200, 60, 50), (230, 230, 230), (60, 60, 60), GLOSSY),
]


@dataclass
class Builder:
    """Adds furniture to a :class:`MeshBuilder` and collects the movable parts."""

    mesh: MeshBuilder
    rng: np.random.Generator
    parts: list[PartSpec] = field(default_factory=list)
    statics: dict[str, str] = field(default_factory=dict)   # key -> GT label of static parts
    counter: dict[str, int] = field(default_factory=dict)

    def _name(self, base: str) -> str:
        self.counter[base] = self.counter.get(base, 0) + 1
        return f"{base}_{self.counter[base]}"

    # -- joints -------------------------------------------------------------------------------
    @staticmethod
    def _world_joint(frame: WallFrame, jt: str, axis, origin, upper: float) -> Articulation:  # noqa: ANN001
        T = frame.T
        return Articulation(joint_type=jt, axis=T[:3, :3] @ np.asarray(axis, float),
                            origin=T[:3, :3] @ np.asarray(origin, float) + T[:3, 3], lower=0.0, upper=upper,
                            limit_source="gt")

    # -- pieces -------------------------------------------------------------------------------
    def front(self, frame: WallFrame, name: str, kind: str, x0: float, x1: float, z0: float, z1: float,
              pal: Palette, handle: bool, carcass_key: str | None, depth: float | None, label_base: str,
              thickness: float = FRONT) -> PartSpec:
        """A front slab over the opening [x0,x1]x[z0,z1] with its joint (and optionally a handle)."""
        T = frame.T
        key = name
        y0, y1 = -PROUD - thickness, -PROUD
        self.mesh.add_box([x0, y0, z0], [x1, y1, z1], pal.front, key, T, material=pal.material)
        ym = 0.5 * (y0 + y1)
        zm, xm = 0.5 * (z0 + z1), 0.5 * (x0 + x1)
        w, h = x1 - x0, z1 - z0
        if kind == "door_left":        # hinge on the left edge, opens towards the room
            art = self._world_joint(frame, "revolute", [0, 0, -1], [x0, ym, zm], float(np.radians(self.rng.uniform(95, 110))))
            hx, hz, horiz = x1 - 0.05, z1 - 0.18 * h if h > 0.5 else zm, False
        elif kind == "door_right":
            art = self._world_joint(frame, "revolute", [0, 0, 1], [x1, ym, zm], float(np.radians(self.rng.uniform(95, 110))))
            hx, hz, horiz = x0 + 0.05, z1 - 0.18 * h if h > 0.5 else zm, False
        elif kind == "flap":           # top-hinged (wall cabinet), opens upwards
            art = self._world_joint(frame, "revolute", [-1, 0, 0], [xm, ym, z1], float(np.radians(self.rng.uniform(75, 90))))
            hx, hz, horiz = xm, z0 + 0.05, True
        elif kind == "drop":           # bottom-hinged (oven, dishwasher), opens downwards
            art = self._world_joint(frame, "revolute", [1, 0, 0], [xm, ym, z0], float(np.radians(85.0)))
            hx, hz, horiz = xm, z1 - 0.06, True
        elif kind == "drawer":
            travel = 0.85 * depth if depth else 0.4
            art = self._world_joint(frame, "prismatic", [0, -1, 0], [xm, ym, zm], float(travel))
            hx, hz, horiz = xm, z1 - min(0.07, 0.3 * h), True
        else:
            raise ValueError(kind)
        hkey = None
        if handle:
            hkey = key + ".handle"
            ln = min(0.8 * (w if horiz else h), self.rng.choice([0.12, 0.16, 0.22]))
            bar, proud = 0.014, 0.032
            if horiz:
                lo, hi = [hx - ln / 2, y0 - proud, hz - bar / 2], [hx + ln / 2, y0, hz + bar / 2]
            else:
                lo, hi = [hx - bar / 2, y0 - proud, hz - ln / 2], [hx + bar / 2, y0, hz + ln / 2]
            self.mesh.add_box(lo, hi, pal.handle, hkey, T, skip=((1, 1),), material=METAL)
        label = f"{label_base}.{kind.split('_')[0]}_{len(self.parts) + 1}"
        spec = PartSpec(key, label, kind.split("_")[0], art, carcass_key, hkey, depth)
        self.parts.append(spec)
        return spec

    def sliding_pair(self, frame: WallFrame, x0: float, x1: float, z0: float, z1: float, pal: Palette, handles: bool,
                     carcass_key: str, depth: float, label_base: str, overlap: float = 0.04, track_gap: float = 0.015) -> None:
        """Two sliding doors over [x0,x1]x[z0,z1] on two tracks: the left one on the outer (room-side) track,
        the right one on the inner track, overlapping by ``overlap`` in the middle. Each slides in the front
        plane towards the other (prismatic along +-x of the wall frame) by its width less the overlap.
        Pulls are flat vertical bars near the outer edges, thinner than ``track_gap`` so a door passes
        behind the other's pull."""
        T = frame.T
        xm = 0.5 * (x0 + x1)
        inner_y = (-PROUD - FRONT, -PROUD)
        outer_y = (inner_y[0] - track_gap - FRONT, inner_y[0] - track_gap)
        doors = [(x0, xm + overlap / 2, outer_y, [1.0, 0.0, 0.0], x0 + 0.05),
                 (xm - overlap / 2, x1, inner_y, [-1.0, 0.0, 0.0], x1 - 0.05)]
        for a, b, (ya, yb), axis, hx in doors:
            key = self._name(carcass_key + "_s")
            self.mesh.add_box([a, ya, z0], [b, yb, z1], pal.front, key, T, material=pal.material)
            travel = (b - a) - overlap
            art = self._world_joint(frame, "prismatic", axis, [0.5 * (a + b), 0.5 * (ya + yb), 0.5 * (z0 + z1)], float(travel))
            hkey = None
            if handles:
                hkey = key + ".handle"
                ln, bar, proud = min(0.3, 0.5 * (z1 - z0)), 0.014, 0.01
                zc = 0.5 * (z0 + z1)
                self.mesh.add_box([hx - bar / 2, ya - proud, zc - ln / 2], [hx + bar / 2, ya, zc + ln / 2], pal.handle, hkey, T,
                                  skip=((1, 1),), material=METAL)
            self.parts.append(PartSpec(key, f"{label_base}.sliding_door_{len(self.parts) + 1}", "sliding", art, carcass_key,
                                       hkey, depth))

    def carcass(self, frame: WallFrame, name: str, W: float, D: float, z0: float, H: float, shelves: list[float],
                pal: Palette, plinth: float = 0.0) -> None:
        """Open-front box: two sides, top, bottom, back and horizontal dividers at heights ``shelves``."""
        T, c, t, mat = frame.T, pal.carcass, BOARD, pal.carcass_material
        m = self.mesh
        edge, m.edge = m.edge, m.edge * 1.8  # boards are mostly hidden: coarser, like a decimated scan
        zt = z0 + H
        if plinth > 0:
            m.add_box([0.02, 0.05, 0.0], [W - 0.02, D, z0], (50, 50, 52), name, T)
        m.add_box([0, 0, z0], [t, D, zt], c, name, T, material=mat)
        m.add_box([W - t, 0, z0], [W, D, zt], c, name, T, material=mat)
        m.add_box([t, 0, z0], [W - t, D - t, z0 + t], c, name, T, material=mat)
        m.add_box([t, 0, zt - t], [W - t, D - t, zt], c, name, T, material=mat)
        m.add_box([t, D - t, z0], [W - t, D, zt], c, name, T, material=mat)
        for z in shelves:
            m.add_box([t, 0, z - t / 2], [W - t, D - t, z + t / 2], c, name, T, material=mat)
        m.edge = edge

    def cabinet(self, frame: WallFrame, W: float, D: float, z0: float, H: float, cells: list[tuple[float, str]],
                pal: Palette, handles: bool, label_base: str, plinth: float = 0.0) -> str:
        """A carcass with a vertical stack of cells (bottom to top): (height fraction, layout).

        Layouts: ``drawer``, ``drawer2`` (two side by side), ``door_left``, ``door_right``, ``door2``
        (a pair), ``flap``, ``drop``, ``slide2`` (a pair of sliding doors on two tracks).
        """
        name = self._name(label_base)
        fr = np.array([f for f, _ in cells], float)
        bounds = z0 + H * np.concatenate([[0.0], np.cumsum(fr / fr.sum())])
        self.carcass(frame, name, W, D, z0, H, list(bounds[1:-1]), pal, plinth)
        self.statics[name] = label_base
        depth = D - BOARD
        g = GAP / 2
        for (_, lay), za, zb in zip(cells, bounds[:-1], bounds[1:]):
            za_, zb_ = za + g, zb - g
            if lay == "slide2":
                self.sliding_pair(frame, g, W - g, za_, zb_, pal, handles, name, depth, label_base)
            elif lay in ("door2", "drawer2"):
                xm = W / 2
                kinds = ("door_left", "door_right") if lay == "door2" else ("drawer", "drawer")
                self.front(frame, self._name(name + "_f"), kinds[0], g, xm - g, za_, zb_, pal, handles, name, depth, label_base)
                self.front(frame, self._name(name + "_f"), kinds[1], xm + g, W - g, za_, zb_, pal, handles, name, depth, label_base)
            else:
                self.front(frame, self._name(name + "_f"), lay, g, W - g, za_, zb_, pal, handles, name, depth, label_base)
        return name

    def static_box(self, frame: WallFrame, lo, hi, color, label: str | None = None,  # noqa: ANN001
                   material: int = MATTE) -> None:
        key = self._name(label) if label else None
        if key:
            self.statics[key] = label  # type: ignore[assignment]
        self.mesh.add_box(lo, hi, color, key, frame.T, material=material)

    def room_door(self, frame: WallFrame, x0: float, width: float, height: float, wall_t: float, pal: Palette) -> None:
        """A door slab in a wall opening [x0, x0+width] x [0, height] (wall frame at the inner wall face),
        with a frame casing; hinged on the left, opening into the room, lever handle on the right."""
        T = frame.T
        name = self._name("door_frame")
        cas, cd = 0.06, 0.015
        x1 = x0 + width
        cm = pal.carcass_material
        self.mesh.add_box([x0 - cas, -cd, 0], [x0, wall_t, height + cas], pal.carcass, name, T, material=cm)
        self.mesh.add_box([x1, -cd, 0], [x1 + cas, wall_t, height + cas], pal.carcass, name, T, material=cm)
        self.mesh.add_box([x0, -cd, height], [x1, wall_t, height + cas], pal.carcass, name, T, material=cm)
        self.statics[name] = "door_frame"
        key = self._name("room_door")
        t = 0.04
        ya, yb = 0.01, 0.01 + t
        self.mesh.add_box([x0 + 0.003, ya, 0.01], [x1 - 0.003, yb, height - 0.003], pal.front, key, T, material=pal.material)
        art = self._world_joint(frame, "revolute", [0, 0, -1], [x0 + 0.003, 0.5 * (ya + yb), height / 2], float(np.radians(100)))
        hkey = key + ".handle"
        hx, hz = x1 - 0.07, 1.0
        self.mesh.add_box([hx - 0.13, ya - 0.055, hz - 0.01], [hx, ya - 0.04, hz + 0.01], pal.handle, hkey, T, material=METAL)
        self.mesh.add_box([hx - 0.012, ya - 0.04, hz - 0.012], [hx + 0.012, ya, hz + 0.012], pal.handle, hkey, T, material=METAL)
        self.parts.append(PartSpec(key, f"door.door_{len(self.parts) + 1}", "room_door", art, name, hkey, None))
