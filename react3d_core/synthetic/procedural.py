"""Procedural rooms: a shell (floor, walls, ceiling) with kitchens, wardrobes, dressers and room doors.

``build_room(seed, kind)`` returns a :class:`SynthLayout`: the merged mesh, the part key of every
face, the movable parts with world joints, and *view runs* (stretches of wall with furniture) that the
camera path sweeps.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..data.mesh import TriMesh
from .builder import MeshBuilder
from .furniture import PALETTES, Builder, PartSpec, WallFrame
from .materials import STONE, WOOD

KINDS = ("kitchen", "wardrobe", "dresser", "room_door", "mixed")  # the default kind is KINDS[seed % 5]
# kinds only built when asked for (so the seed -> kind mapping of existing scenes stays as it was);
# the last four are rooms of free-standing furniture and appliances (rooms.py)
EXTRA_KINDS = ("sliding", "large_kitchen", "furniture", "appliances", "glass", "dark")
ALL_KINDS = KINDS + EXTRA_KINDS
WALL_T = 0.12


@dataclass
class ViewRun:
    """A stretch [x0, x1] of a wall (wall frame at the inner wall face) with furniture between z0 and z1."""

    frame: WallFrame
    x0: float
    x1: float
    z0: float
    z1: float
    depth: float  # how far the furniture sticks out of the wall
    free_depth: float | None = None  # free space in front of the wall (default: from the room size)


@dataclass
class SynthLayout:
    mesh: TriMesh
    face_keys: np.ndarray
    key_ids: dict[str, int]
    parts: list[PartSpec]
    statics: dict[str, str]
    runs: list[ViewRun]
    room: tuple[float, float, float]
    kind: str
    extra: dict = field(default_factory=dict)
    # keep only surfaces a capture of the closed scene observes (see observed.py); URDF models hold
    # internal geometry (drawer boxes, appliance insides) that no scan and no Articulate3D label has
    observed_only: bool = False
    face_materials: np.ndarray | None = None  # per face, see materials.py (None: all matte)
    face_colors: np.ndarray | None = None     # per face albedo for the photo renderer (None: vertex colours)
    gt_boxes: bool = False  # write each movable part's true box and scan coverage in the GT (writer.py)


def wall_frames(W: float, L: float) -> list[tuple[WallFrame, float]]:
    """Wall frames (origin at the left end of each inner wall face, seen from the room) and wall lengths."""
    return [
        (WallFrame(np.array([0.0, L, 0.0]), 0.0), W),
        (WallFrame(np.array([W, L, 0.0]), -np.pi / 2), L),
        (WallFrame(np.array([W, 0.0, 0.0]), np.pi), W),
        (WallFrame(np.array([0.0, 0.0, 0.0]), np.pi / 2), L),
    ]


def shell(m: MeshBuilder, rng: np.random.Generator, W: float, L: float, H: float,
           door: tuple[int, float, float, float] | None) -> None:
    """Floor, ceiling and four walls; ``door`` = (wall index, x0, width, height) cuts an opening."""
    edge, m.edge = m.edge, max(0.12, float(np.sqrt(W * L)) / 35.0)  # plain walls: coarse, like a decimated scan
    wall_col = tuple(int(c) for c in rng.integers(200, 245, 3))
    m.add_box([-WALL_T, -WALL_T, -0.05], [W + WALL_T, L + WALL_T, 0.0], tuple(int(c) for c in rng.integers(110, 170, 3)),
              material=WOOD)
    m.add_box([-WALL_T, -WALL_T, H], [W + WALL_T, L + WALL_T, H + 0.05], (235, 235, 235))
    for k, (fr, length) in enumerate(wall_frames(W, L)):
        T = fr.T
        pieces = [(0.0, length, 0.0, H)]
        if door is not None and door[0] == k:
            _, x0, dw, dh = door
            pieces = [(0.0, x0, 0.0, H), (x0 + dw, length, 0.0, H), (x0, x0 + dw, dh, H)]
        for a, b, z0, z1 in pieces:
            m.add_box([a, 0.0, z0], [b, WALL_T, z1], wall_col, None, T)
    if door is not None:  # a dark corridor behind the door so the opening is not a hole in the world
        fr, _ = wall_frames(W, L)[door[0]]
        _, x0, dw, dh = door
        m.add_box([x0 - 0.5, WALL_T + 1.2, 0.0], [x0 + dw + 0.5, WALL_T + 1.3, H], (90, 90, 95), None, fr.T)
        m.add_box([x0 - 0.5, WALL_T, -0.05], [x0 + dw + 0.5, WALL_T + 1.2, 0.0], (120, 110, 100), None, fr.T, material=WOOD)
    m.edge = edge


def _kitchen(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun], H: float,
             max_units: int = 5, wall_p: float = 0.7, x_min: float = 0.0) -> None:
    """A run of base units under a worktop, with wall cabinets above it ``wall_p`` of the time; the run
    starts at least ``x_min`` along the wall (clear of another run in the corner)."""
    pal = PALETTES[int(rng.integers(len(PALETTES)))]
    handles = bool(rng.random() < 0.75)
    x = max(x_min, float(rng.uniform(0.1, 0.4)))
    D, Hb, plinth = float(rng.uniform(0.52, 0.62)), float(rng.uniform(0.78, 0.86)), 0.1
    x_start = x
    widths = []
    while True:
        w = float(rng.choice([0.4, 0.45, 0.5, 0.6, 0.6, 0.8]))
        if x + w > length - 0.2 or len(widths) >= max_units:
            break
        widths.append(w)
        x += w
    appliance = rng.random() < 0.5 and len(widths) >= 3
    x = x_start
    for i, w in enumerate(widths):
        f = fr.shifted(x, -D)
        r = rng.random()
        if appliance and i == 1:
            cells = [(1.0, "drop")] if w <= 0.6 else [(0.25, "drawer"), (0.75, "drop")]
        elif r < 0.3:
            cells = [(0.75, "door2" if w >= 0.6 else ("door_left" if rng.random() < 0.5 else "door_right")), (0.25, "drawer")]
        elif r < 0.6:
            cells = [(0.34, "drawer"), (0.33, "drawer"), (0.33, "drawer")]
        else:
            cells = [(1.0, "door2" if w >= 0.6 else ("door_left" if rng.random() < 0.5 else "door_right"))]
        b.cabinet(f, w, D, plinth, Hb - plinth, cells, pal, handles, "kitchen_cabinet", plinth=plinth)
        x += w
    total = x - x_start
    if total <= 0:
        return
    b.static_box(fr.shifted(x_start, -D - 0.02), [0, 0, Hb], [total, D + 0.02, Hb + 0.03], (70, 70, 72), "countertop", material=STONE)
    z1 = Hb + 0.03
    if rng.random() < wall_p and H > 2.3:  # wall cabinets
        Dw, z0w, Hw = 0.35, Hb + 0.6, min(0.7, H - Hb - 0.7)
        x = x_start
        top_hinged = rng.random() < 0.5
        for w in widths:
            cells = [(1.0, "flap" if top_hinged else ("door2" if w >= 0.6 else "door_left"))]
            b.cabinet(fr.shifted(x, -Dw), w, Dw, z0w, Hw, cells, pal, handles, "wall_cabinet")
            x += w
        z1 = z0w + Hw
    runs.append(ViewRun(fr, x_start, x_start + total, 0.1, z1, D))


def _wardrobe(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun], H: float) -> None:
    pal = PALETTES[int(rng.integers(len(PALETTES)))]
    D, Ht = float(rng.uniform(0.55, 0.65)), float(min(H - 0.15, rng.uniform(1.9, 2.2)))
    n = int(rng.integers(1, 3))
    x0 = float(rng.uniform(0.2, max(0.25, length - n * 1.0 - 0.2)))
    x = x0
    for _ in range(n):
        w = float(rng.uniform(0.8, 1.0))
        if x + w > length - 0.1:
            break
        cells = [(0.2, "drawer2"), (0.8, "door2")] if rng.random() < 0.5 else [(1.0, "door2")]
        b.cabinet(fr.shifted(x, -D), w, D, 0.05, Ht - 0.05, cells, pal, bool(rng.random() < 0.8), "wardrobe", plinth=0.05)
        x += w
    if x > x0:
        runs.append(ViewRun(fr, x0, x, 0.05, Ht, D))


def _dresser(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun], H: float) -> None:
    pal = PALETTES[int(rng.integers(len(PALETTES)))]
    D, Hd = float(rng.uniform(0.42, 0.5)), float(rng.uniform(0.75, 1.1))
    n_rows = int(rng.integers(3, 6))
    w = float(rng.uniform(0.7, 1.2))
    x0 = float(rng.uniform(0.2, max(0.25, length - w - 0.2)))
    cells = [(1.0, "drawer2" if (w > 0.9 and i >= n_rows - 2) else "drawer") for i in range(n_rows)]
    b.cabinet(fr.shifted(x0, -D), w, D, 0.08, Hd, cells, pal, bool(rng.random() < 0.85), "dresser", plinth=0.08)
    x = x0 + w
    if x + 0.5 < length - 0.1 and rng.random() < 0.6:  # a nightstand: drawer over a door
        b.cabinet(fr.shifted(x + 0.1, -0.4), 0.45, 0.4, 0.06, 0.55, [(0.6, "door_left"), (0.4, "drawer")], pal, True,
                  "nightstand", plinth=0.06)
        x += 0.55
    runs.append(ViewRun(fr, x0, x, 0.08, 0.08 + Hd, D))


def _sliding(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun], H: float) -> None:
    """A low sideboard / TV cabinet with a pair of sliding doors (above a drawer row half the time) and a
    sliding-door wardrobe beside it: sliding doors with GT joints in the front plane."""
    pal = PALETTES[int(rng.integers(len(PALETTES)))]
    handles = bool(rng.random() < 0.8)
    D, Hs, w = float(rng.uniform(0.4, 0.48)), float(rng.uniform(0.55, 0.8)), float(rng.uniform(1.2, 1.6))
    x0 = float(rng.uniform(0.15, 0.35))
    cells = [(0.25, "drawer2"), (0.75, "slide2")] if rng.random() < 0.5 else [(1.0, "slide2")]
    b.cabinet(fr.shifted(x0, -D), w, D, 0.08, Hs, cells, pal, handles, "sideboard", plinth=0.08)
    x, z1, depth = x0 + w, 0.08 + Hs, D
    ww = float(rng.uniform(1.4, 1.8))
    if x + 0.1 + ww < length - 0.1:
        Dw, Ht = float(rng.uniform(0.58, 0.65)), float(min(H - 0.15, rng.uniform(1.9, 2.2)))
        b.cabinet(fr.shifted(x + 0.1, -Dw), ww, Dw, 0.05, Ht - 0.05, [(1.0, "slide2")], pal, handles, "wardrobe", plinth=0.05)
        x, z1, depth = x + 0.1 + ww, Ht, Dw
    runs.append(ViewRun(fr, x0, x, 0.08, z1, depth))


def _long_kitchen(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun],
                  H: float, x_min: float = 0.0) -> None:
    """A full wall of base units (up to 8) with wall cabinets over all of them: two such walls (an L)
    hold 32-52 openable parts (42 on average over 30 seeds), like the large kitchens of real rooms."""
    _kitchen(b, fr, length, rng, runs, H, max_units=8, wall_p=1.0, x_min=x_min)


def _corner_kitchen(b: Builder, fr: WallFrame, length: float, rng: np.random.Generator, runs: list[ViewRun],
                    H: float) -> None:
    """The second leg of the L: it starts past the first leg's units in the corner (0.62 m deep at most)."""
    _long_kitchen(b, fr, length, rng, runs, H, x_min=0.72)


def build_room(seed: int, kind: str | None = None, edge: float = 0.03) -> SynthLayout:
    """A seeded room of the given kind (default: chosen by seed)."""
    kind = kind or KINDS[seed % len(KINDS)]
    if kind not in ALL_KINDS:
        raise ValueError(f"unknown scene kind {kind!r}; choose from {', '.join(ALL_KINDS)}")
    if kind in EXTRA_KINDS[2:]:
        from .rooms import build_free_room

        return build_free_room(seed, kind, edge)
    rng = np.random.default_rng(seed)
    W, L, H = float(rng.uniform(3.4, 4.6)), float(rng.uniform(3.8, 5.2)), float(rng.uniform(2.5, 2.8))
    m = MeshBuilder(edge=edge, seed=seed)
    b = Builder(m, rng)
    runs: list[ViewRun] = []
    frames = wall_frames(W, L)
    door = None
    if kind in ("room_door", "mixed"):
        k = 3 if kind == "room_door" else 2
        length = frames[k][1]
        dw = float(rng.uniform(0.8, 0.95))
        door = (k, float(rng.uniform(0.4, length - dw - 0.4)), dw, float(rng.uniform(2.0, 2.1)))
    shell(m, rng, W, L, H, door)
    if door is not None:
        fr = frames[door[0]][0]
        b.room_door(fr, door[1], door[2], door[3], WALL_T, PALETTES[int(rng.integers(len(PALETTES)))])
        runs.append(ViewRun(fr, door[1] - 0.1, door[1] + door[2] + 0.1, 0.0, door[3], 0.05))
    plan = {
        "kitchen": [(0, _kitchen)],
        "wardrobe": [(0, _wardrobe)],
        "dresser": [(0, _dresser)],
        "room_door": [(0, _dresser), (1, _wardrobe)],
        "mixed": [(0, _kitchen), (1, _wardrobe), (3, _dresser)],
        "sliding": [(0, _sliding), (1, _dresser)],
        "large_kitchen": [(0, _long_kitchen), (1, _corner_kitchen)],
    }[kind]
    for k, fn in plan:
        fr, length = frames[k]
        fn(b, fr, length, rng, runs, H)
    mesh, keys, key_ids = m.build()
    return SynthLayout(mesh, keys, key_ids, b.parts, b.statics, runs, (W, L, H), kind, face_materials=m.materials(),
                       face_colors=m.base_colors())
