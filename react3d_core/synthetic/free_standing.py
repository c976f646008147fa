"""Free-standing furniture: desks with drawer pedestals, nightstands, chests of drawers, filing
cabinets, low and tall cabinets, wardrobes, sideboards and glass-door cupboards.

Each ``*_piece`` draws its size and layout from the generator and returns a :class:`Piece`: its
footprint (``w`` along the front, ``d`` deep), height, and a ``build(frame)`` that adds it to the
scene at a wall frame whose origin is the piece's front-left-bottom corner (front at y = 0, +y into
the piece). Sizes are those of real furniture; drawer fronts go down to ~10 cm.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .fronts import DARK, FINISHES, HANDLE_STYLES, LIGHT, Finish, PieceBuilder
from .furniture import WallFrame


@dataclass
class Piece:
    """One piece to place: footprint, height, how to build it, where its fronts are (z range)."""

    name: str
    w: float
    d: float
    h: float
    build: Callable[[WallFrame], None]
    z_fronts: tuple[float, float]
    wall_gap: float = 0.0          # stands this far off the wall (appliances need air)
    free_ok: bool = True           # may stand free in the room (its back is finished)
    openable: bool = True          # has movable fronts (clutter has none)
    extra_h: float = 0.0           # something stands on it (microwave): its camera run reaches higher
    tags: list[str] = field(default_factory=list)


def pick_finish(rng: np.random.Generator, dark: bool | None = None) -> Finish:
    """A furniture finish: light or dark (``None``: dark one time in five)."""
    if dark is None:
        dark = bool(rng.random() < 0.2)
    names = DARK if dark else LIGHT
    return FINISHES[names[int(rng.integers(len(names)))]]


def pick_handle(rng: np.random.Generator) -> str:
    return HANDLE_STYLES[int(rng.integers(len(HANDLE_STYLES)))]


def _base(rng: np.random.Generator) -> tuple[float, float]:
    """(legs, plinth) under a body: on legs (10-20 cm) or on a recessed plinth (5-8 cm)."""
    if rng.random() < 0.5:
        return float(rng.uniform(0.1, 0.2)), 0.0
    return 0.0, float(rng.uniform(0.05, 0.08))


def desk_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A desk: a top on one or two drawer pedestals (3-4 drawers, fronts from 12 cm), legs where there
    is no pedestal, and a 9-11 cm pencil drawer under the top 40 % of the time."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    W, D, H, t = float(rng.uniform(1.2, 1.8)), float(rng.uniform(0.6, 0.8)), float(rng.uniform(0.72, 0.76)), 0.03
    two = bool(rng.random() < 0.35)
    left = bool(rng.random() < 0.5)
    pw = float(rng.uniform(0.4, 0.46))
    stacks = [[(1, "drawer")] * 3, [(1, "drawer")] * 4, [(0.55, "drawer"), (0.225, "drawer"), (0.225, "drawer")],
              [(1, "drawer"), (1, "drawer"), (1, "drawer"), (0.7, "drawer")]]
    stack = stacks[int(rng.integers(len(stacks)))]
    pencil = bool(rng.random() < 0.4)
    ph = float(rng.uniform(0.09, 0.11))

    def build(fr: WallFrame) -> None:
        top_col = fin.body
        b.static_box(fr, [-0.01, -0.02, H - t], [W + 0.01, D, H], top_col, "desk_top", material=fin.body_mat)
        zp = H - t - 0.004
        spots = [0.01, W - pw - 0.01] if two else ([0.01] if left else [W - pw - 0.01])
        for x in spots:
            b.grid(fr.shifted(x, 0.0), "desk", pw, D - 0.06, 0.02, zp - 0.02, [(1.0, stack)], fin, handle)
        if not two:  # two panel legs at the free end
            xl = W - 0.05 if left else 0.01
            b.static_box(fr, [xl, 0.05, 0.0], [xl + 0.04, D - 0.05, H - t], fin.body, "desk_leg", material=fin.body_mat)
        if pencil:
            x0 = pw + 0.06 if (two or left) else 0.1
            x1 = W - pw - 0.06 if (two or not left) else W - 0.1
            if x1 - x0 > 0.35:
                xm, wp = 0.5 * (x0 + x1), min(0.6, x1 - x0)
                b.grid(fr.shifted(xm - wp / 2, 0.0), "desk", wp, D - 0.15, zp - ph, ph, [(1.0, [(1, "drawer")])], fin,
                       "edge" if handle == "none" else handle)

    return Piece("desk", W, D, H, build, (0.02, H), tags=["office"])


def nightstand_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A nightstand: two or three low drawers, a drawer over an open niche or over a door."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    W, D, H = float(rng.uniform(0.4, 0.55)), float(rng.uniform(0.35, 0.45)), float(rng.uniform(0.45, 0.65))
    legs, plinth = _base(rng)
    z0 = max(legs, plinth)
    layouts = [[(1, "drawer"), (1, "drawer")], [(1, "drawer")] * 3, [(0.65, "shelf"), (0.35, "drawer")],
               [(0.62, "door_left" if rng.random() < 0.5 else "door_right"), (0.38, "drawer")]]
    cells = layouts[int(rng.integers(len(layouts)))]

    def build(fr: WallFrame) -> None:
        b.grid(fr, "nightstand", W, D, z0, H - z0, [(1.0, cells)], fin, handle, legs=legs, plinth=plinth)

    return Piece("nightstand", W, D, H, build, (z0, H), tags=["bedroom"])


def chest_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A chest of drawers: 3-6 rows, the lower rows split in two on wide chests."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    W, D, H = float(rng.uniform(0.6, 1.2)), float(rng.uniform(0.42, 0.5)), float(rng.uniform(0.7, 1.1))
    legs, plinth = _base(rng)
    z0 = max(legs, plinth)
    n = int(rng.integers(3, 7))
    cells = [(1.0, "drawer2" if (W > 0.9 and i < 2) else "drawer") for i in range(n)]

    def build(fr: WallFrame) -> None:
        b.grid(fr, "chest", W, D, z0, H - z0, [(1.0, cells)], fin, handle, legs=legs, plinth=plinth)

    return Piece("chest", W, D, H, build, (z0, H), tags=["bedroom"])


def filing_cabinet_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A steel (or painted) filing cabinet: 3 drawers at desk height or 4 at 1.3 m."""
    names = ["steel", "light_grey", "anthracite", "black_matte", "white_matte"]
    fin = fin or FINISHES[names[int(rng.integers(len(names)))]]
    handle = ["bar", "edge", "knob"][int(rng.integers(3))]
    tall = bool(rng.random() < 0.4)
    W, D, H = float(rng.uniform(0.4, 0.47)), float(rng.uniform(0.55, 0.62)), (1.32 if tall else 0.72)
    cells = [(1.0, "drawer")] * (4 if tall else 3)

    def build(fr: WallFrame) -> None:
        b.grid(fr, "filing_cabinet", W, D, 0.03, H - 0.03, [(1.0, cells)], fin, handle, plinth=0.03)

    return Piece("filing_cabinet", W, D, H, build, (0.03, H), tags=["office"])


def cabinet_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A free-standing cabinet: low (one or two doors, a drawer row on top half the time) or tall (two
    doors, a drawer at the bottom half the time)."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    tall = bool(rng.random() < 0.45)
    W, D = float(rng.uniform(0.6, 1.0)), float(rng.uniform(0.38, 0.55))
    H = float(rng.uniform(1.6, 2.0)) if tall else float(rng.uniform(0.8, 1.0))
    legs, plinth = _base(rng)
    z0 = max(legs, plinth)
    doors = "door2" if W >= 0.7 else ("door_left" if rng.random() < 0.5 else "door_right")
    if tall:
        cells = [(0.15, "drawer2" if W >= 0.7 else "drawer"), (0.85, doors)] if rng.random() < 0.5 else [(1.0, doors)]
    else:
        cells = [(0.78, doors), (0.22, "drawer2" if W >= 0.7 else "drawer")] if rng.random() < 0.5 else [(1.0, doors)]

    def build(fr: WallFrame) -> None:
        b.grid(fr, "cabinet", W, D, z0, H - z0, [(1.0, cells)], fin, handle, legs=legs, plinth=plinth)

    return Piece("cabinet", W, D, H, build, (z0, H), tags=["living", "office"])


def wardrobe_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A free-standing wardrobe: two or three doors, a drawer row at the bottom half the time, a cornice."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    three = bool(rng.random() < 0.4)
    W = float(rng.uniform(1.2, 1.6)) if three else float(rng.uniform(0.9, 1.2))
    D, H = float(rng.uniform(0.55, 0.62)), float(rng.uniform(1.9, 2.15))
    drawers = bool(rng.random() < 0.5)
    z0 = 0.06

    def col(lay: str) -> list[tuple[float, str]]:
        if drawers:
            return [(0.14, "drawer2" if lay == "door2" else "drawer"), (0.86, lay)]
        return [(1.0, lay)]

    columns = [(1.0, col("door_left")), (2.0, col("door2"))] if three else [(1.0, col("door2"))]

    def build(fr: WallFrame) -> None:
        b.grid(fr, "wardrobe", W, D, z0, H - z0 - 0.04, columns, fin, handle, plinth=z0)
        b.static_box(fr, [-0.02, -0.03, H - 0.04], [W + 0.02, D, H], fin.body, "cornice", material=fin.body_mat)

    return Piece("wardrobe", W, D, H, build, (z0, H - 0.04), free_ok=False, tags=["bedroom"])


def sideboard_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None,
                    glass_p: float = 0.0) -> Piece:
    """A sideboard: 2-4 columns of doors, drawer stacks, door-under-drawer and open niches on legs or a
    plinth; ``glass_p``: chance that a door column has glass-panel doors."""
    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    W, D, H = float(rng.uniform(1.2, 2.0)), float(rng.uniform(0.42, 0.5)), float(rng.uniform(0.7, 0.9))
    legs, plinth = _base(rng)
    z0 = max(legs, plinth)
    n = int(np.clip(round(W / 0.5), 2, 4))
    columns = []
    for _ in range(n):
        r = rng.random()
        glass = bool(rng.random() < glass_p)
        door = ("glass_left" if glass else "door_left") if rng.random() < 0.5 else ("glass_right" if glass else "door_right")
        if r < 0.35:
            columns.append((1.0, [(1.0, door)]))
        elif r < 0.65:
            columns.append((1.0, [(1.0, "drawer")] * int(rng.integers(2, 4))))
        elif r < 0.9:
            columns.append((1.0, [(0.75, door), (0.25, "drawer")]))
        else:
            columns.append((1.0, [(1.0, "shelf")]))

    def build(fr: WallFrame) -> None:
        b.grid(fr, "sideboard", W, D, z0, H - z0 - 0.025, columns, fin, handle, legs=legs, plinth=plinth)
        b.static_box(fr, [-0.01, -0.01, H - 0.025], [W + 0.01, D, H], fin.body, "sideboard_top", material=fin.body_mat)

    return Piece("sideboard", W, D, H, build, (z0, H), tags=["living"])


def display_cupboard_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None,
                           glass_p: float = 1.0) -> Piece:
    """A cupboard of 2-4 columns: solid doors below, glass-panel doors above (books and cups behind
    them), a drawer row between them half the time."""
    fin = fin or pick_finish(rng, dark=False)
    handle = ["bar", "knob", "knob", "edge"][int(rng.integers(4))]
    n = int(rng.integers(2, 5))
    W = float(n * rng.uniform(0.4, 0.5))
    D, H = float(rng.uniform(0.4, 0.48)), float(rng.uniform(1.8, 2.1))
    mid = bool(rng.random() < 0.5)
    columns = []
    for i in range(n):
        side = "left" if i % 2 == 0 else "right"
        top = "glass" if rng.random() < glass_p else "door"
        cells = [(0.4, f"door_{side}")] + ([(0.1, "drawer")] if mid else []) + [(0.5, f"{top}_{side}")]
        columns.append((1.0, cells))

    def build(fr: WallFrame) -> None:
        b.grid(fr, "cupboard", W, D, 0.07, H - 0.07 - 0.04, columns, fin, handle, plinth=0.07)
        b.static_box(fr, [-0.02, -0.03, H - 0.04], [W + 0.02, D, H], fin.body, "cornice", material=fin.body_mat)

    return Piece("cupboard", W, D, H, build, (0.07, H - 0.04), free_ok=False, tags=["living", "glass"])


def vitrine_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None, glass_p: float = 1.0) -> Piece:
    """A tall vitrine: one or two glass-panel doors over its whole height, shelves with things behind."""
    fin = fin or pick_finish(rng, dark=False)
    handle = ["bar", "knob", "none"][int(rng.integers(3))]
    two = bool(rng.random() < 0.5)
    W = float(rng.uniform(0.8, 1.0)) if two else float(rng.uniform(0.45, 0.6))
    D, H = float(rng.uniform(0.35, 0.42)), float(rng.uniform(1.6, 1.95))
    lay = "glass2" if two else ("glass_left" if rng.random() < 0.5 else "glass_right")
    if rng.random() >= glass_p:
        lay = lay.replace("glass", "door")

    def build(fr: WallFrame) -> None:
        b.grid(fr, "vitrine", W, D, 0.06, H - 0.06, [(1.0, [(1.0, lay)])], fin, handle, plinth=0.06)

    return Piece("vitrine", W, D, H, build, (0.06, H), free_ok=False, tags=["living", "glass"])


def kitchen_run_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None, glass_p: float = 0.8,
                      max_units: int = 3) -> Piece:
    """A short kitchen run against a wall: 2..``max_units`` base units (doors and drawers) under a
    worktop and wall cabinets above it, each with glass-panel doors with chance ``glass_p``."""
    fin = fin or pick_finish(rng, dark=False)
    handle = pick_handle(rng)
    n = int(rng.integers(2, max_units + 1))
    widths = [float(rng.choice([0.4, 0.5, 0.6])) for _ in range(n)]
    W = float(sum(widths))
    D, Hb, Dw = float(rng.uniform(0.55, 0.6)), float(rng.uniform(0.85, 0.9)), 0.35
    z0w, Hw = Hb + float(rng.uniform(0.5, 0.6)), float(rng.uniform(0.6, 0.72))
    base_cells = []
    for w in widths:
        r = rng.random()
        door = "door2" if w >= 0.6 else ("door_left" if rng.random() < 0.5 else "door_right")
        base_cells.append([(1.0, door)] if r < 0.5 else ([(1, "drawer")] * 3 if r < 0.8 else [(0.75, door), (0.25, "drawer")]))
    wall_cells = []
    for w in widths:
        glass = rng.random() < glass_p
        lay = ("glass2" if glass else "door2") if w >= 0.6 else (("glass_left" if glass else "door_left") if rng.random() < 0.5
                                                                   else ("glass_right" if glass else "door_right"))
        wall_cells.append([(1.0, lay)])

    def build(fr: WallFrame) -> None:
        x = 0.0
        for w, cells in zip(widths, base_cells):
            b.grid(fr.shifted(x, 0.0), "kitchen_cabinet", w, D, 0.1, Hb - 0.13, [(1.0, cells)], fin, handle, plinth=0.1)
            x += w
        b.static_box(fr, [0.0, -0.02, Hb - 0.03], [W, D, Hb], (70, 70, 72), "countertop", material=4)
        x = 0.0
        for w, cells in zip(widths, wall_cells):
            b.grid(fr.shifted(x, D - Dw), "wall_cabinet", w, Dw, z0w, Hw, [(1.0, cells)], fin, handle)
            x += w

    return Piece("kitchen_run", W, D, z0w + Hw, build, (0.1, z0w + Hw), free_ok=False, tags=["kitchen", "glass"])
