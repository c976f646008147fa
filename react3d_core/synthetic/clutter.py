"""Things in a room that do not open: chairs, tables, boxes, plants, bookshelves, a bed, a floor lamp,
pictures and a radiator on the walls.

They are the distractors a front detector meets in real rooms: seams between books and boards, a
chair's top rail and a box's hand hold that look like handles, picture frames that look like fronts.
None is a GT part (no key). Floor pieces return a :class:`~.free_standing.Piece` (``openable=False``)
so they are placed like furniture; wall pieces are added directly.
"""

from __future__ import annotations

import numpy as np

from .free_standing import Piece
from .fronts import FINISHES, LIGHT, Y_UP, PieceBuilder
from .furniture import WallFrame
from .materials import GLOSSY, METAL, WOOD


def _col(rng: np.random.Generator, lo: int = 40, hi: int = 220) -> tuple[int, int, int]:
    return tuple(int(v) for v in rng.integers(lo, hi, 3))  # type: ignore[return-value]


def chair_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """A chair: four legs, a seat, two back posts with a top rail (a handle look-alike) and a slat."""
    fin = FINISHES[LIGHT[int(rng.integers(len(LIGHT)))]]
    W, D, hs, hb = float(rng.uniform(0.42, 0.48)), float(rng.uniform(0.42, 0.5)), float(rng.uniform(0.44, 0.48)), float(rng.uniform(0.82, 0.95))
    col, mat = fin.body, fin.body_mat

    def build(fr: WallFrame) -> None:
        T, m, s = fr.T, b.mesh, 0.03
        for x in (0.0, W - s):
            for y in (0.0, D - s):
                m.add_box([x, y, 0.0], [x + s, y + s, hs - 0.03], col, None, T, material=mat)
        m.add_box([0.0, 0.0, hs - 0.03], [W, D, hs], col, None, T, material=mat)
        for x in (0.0, W - s):
            m.add_box([x, D - s, hs], [x + s, D, hb], col, None, T, material=mat)
        m.add_box([0.0, D - s, hb - 0.06], [W, D, hb], col, None, T, material=mat)
        m.add_box([s, D - 0.02, hs + 0.15], [W - s, D - 0.01, hs + 0.19], col, None, T, material=mat)

    return Piece("chair", W, D, hb, build, (0.0, hb), openable=False)


def table_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """A table on four legs, sometimes with a box or a bowl on it."""
    fin = FINISHES[LIGHT[int(rng.integers(len(LIGHT)))]]
    W, D, H = float(rng.uniform(0.8, 1.6)), float(rng.uniform(0.6, 0.9)), float(rng.uniform(0.72, 0.76))
    thing = int(rng.integers(3))

    def build(fr: WallFrame) -> None:
        T, m, s = fr.T, b.mesh, 0.05
        for x in (0.03, W - 0.03 - s):
            for y in (0.03, D - 0.03 - s):
                m.add_box([x, y, 0.0], [x + s, y + s, H - 0.03], fin.body, None, T, material=fin.body_mat)
        m.add_box([0.0, 0.0, H - 0.03], [W, D, H], fin.body, None, T, material=fin.body_mat)
        if thing == 1:
            m.add_box([0.2 * W, 0.3 * D, H], [0.2 * W + 0.3, 0.3 * D + 0.22, H + 0.18], (160, 120, 80), None, T)
        elif thing == 2:
            m.add_cylinder(0.6 * W, -0.5 * D, H, H + 0.08, 0.12, _col(rng, 120, 240), None, T @ Y_UP, material=GLOSSY)

    return Piece("table", W, D, H, build, (0.0, H), openable=False)


def boxes_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """One or two cardboard boxes (stacked): tape along the top and a hand-hold slot in the side."""
    W, D, H = float(rng.uniform(0.35, 0.6)), float(rng.uniform(0.3, 0.45)), float(rng.uniform(0.25, 0.4))
    two = bool(rng.random() < 0.5)
    brown = (int(rng.integers(150, 185)), int(rng.integers(115, 140)), int(rng.integers(75, 95)))

    def build(fr: WallFrame) -> None:
        T, m = fr.T, b.mesh
        for k in range(2 if two else 1):
            z0, sh = k * H, 0.04 * k
            m.add_box([sh, sh, z0], [W - sh, D - sh, z0 + H], brown, None, T)
            m.add_box([W / 2 - 0.025, sh - 0.001, z0 + H - 0.01], [W / 2 + 0.025, D - sh + 0.001, z0 + H + 0.001], (200, 190, 160), None, T)
            m.add_box([W / 2 - 0.06, sh - 0.002, z0 + H - 0.09], [W / 2 + 0.06, sh, z0 + H - 0.06], (35, 28, 20), None, T)

    return Piece("boxes", W, D, H * (2 if two else 1), build, (0.0, H), openable=False)


def plant_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """A potted plant: a round pot and a stack of green discs (foliage), up to 1.1 m."""
    r, hp = float(rng.uniform(0.12, 0.2)), float(rng.uniform(0.2, 0.35))
    ht = float(rng.uniform(0.4, 0.75))
    pot = _col(rng, 60, 230)

    def build(fr: WallFrame) -> None:
        T = fr.T @ Y_UP
        m = b.mesh
        m.add_cylinder(r, -r, 0.0, hp, r, pot, None, T, material=GLOSSY)
        n = 5
        for k in range(n):
            z = hp + k * ht / n
            rr = (1.6 - 1.2 * k / n) * r * float(rng.uniform(0.85, 1.15))
            m.add_cylinder(r + float(rng.uniform(-0.03, 0.03)), -r, z, z + ht / n, rr,
                           (int(rng.integers(40, 70)), int(rng.integers(95, 140)), int(rng.integers(40, 70))), None, T)

    return Piece("plant", 2 * r, 2 * r, hp + ht, build, (0.0, hp + ht), openable=False)


def bookshelf_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """An open bookshelf (no doors): boards and rows of books, seams everywhere."""
    fin = FINISHES[LIGHT[int(rng.integers(len(LIGHT)))]]
    W, D, H = float(rng.uniform(0.6, 1.0)), float(rng.uniform(0.28, 0.35)), float(rng.uniform(1.1, 1.9))
    n = max(2, int(H / 0.35))

    def build(fr: WallFrame) -> None:
        name = b._name("bookshelf")
        zs = [0.05 + (H - 0.05) * (k + 1) / n for k in range(n - 1)]
        b.body(fr, name, W, D, 0.05, H - 0.05, fin, [(0.018, W - 0.018, z) for z in zs], plinth=0.05)
        b.statics.pop(name, None)  # not a GT part: a bookshelf has nothing that opens
        for za, zb in zip([0.05 + 0.009] + [z + 0.009 for z in zs], zs + [H - 0.018]):
            if rng.random() < 0.85:
                b.shelf_items(fr, 0.02, W - 0.02, za, D, zb - za - 0.02)

    return Piece("bookshelf", W, D, H, build, (0.05, H), openable=False)


def bed_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """A bed: a base, a mattress, a pillow and a headboard (against a wall, head first)."""
    fin = FINISHES[LIGHT[int(rng.integers(len(LIGHT)))]]
    W, D = float(rng.choice([0.9, 1.4, 1.6])), float(rng.uniform(2.0, 2.1))
    sheet = _col(rng, 150, 245)

    def build(fr: WallFrame) -> None:
        T, m = fr.T, b.mesh
        m.add_box([0.0, 0.0, 0.05], [W, D, 0.3], fin.body, None, T, material=fin.body_mat)
        m.add_box([0.02, 0.02, 0.3], [W - 0.02, D - 0.05, 0.5], sheet, None, T)
        m.add_box([0.1, D - 0.5, 0.5], [W - 0.1, D - 0.12, 0.62], (240, 240, 236), None, T)
        m.add_box([0.0, D - 0.05, 0.0], [W, D, 1.0], fin.body, None, T, material=fin.body_mat)

    return Piece("bed", W, D, 1.0, build, (0.0, 1.0), openable=False)


def lamp_piece(b: PieceBuilder, rng: np.random.Generator) -> Piece:
    """A floor lamp: a round base, a pole and a shade (1.5-1.7 m)."""
    H = float(rng.uniform(1.5, 1.7))

    def build(fr: WallFrame) -> None:
        T, m = fr.T @ Y_UP, b.mesh
        m.add_cylinder(0.15, -0.15, 0.0, 0.03, 0.14, (40, 40, 42), None, T, material=METAL)
        m.add_cylinder(0.15, -0.15, 0.03, H - 0.3, 0.012, (40, 40, 42), None, T, material=METAL)
        m.add_cylinder(0.15, -0.15, H - 0.3, H, 0.15, (235, 225, 200), None, T)

    return Piece("lamp", 0.3, 0.3, H, build, (0.0, H), openable=False)


def wall_decor(b: PieceBuilder, fr: WallFrame, length: float, H: float, rng: np.random.Generator,
               taken: list[tuple[float, float]]) -> None:
    """Pictures (a frame around a print: looks like a front) and a radiator with a valve knob on a
    wall, in stretches [x0, x1] not in ``taken``."""
    T, m = fr.T, b.mesh

    def free(x0: float, x1: float) -> bool:
        return x0 > 0.1 and x1 < length - 0.1 and all(x1 < a - 0.05 or x0 > c + 0.05 for a, c in taken)

    for _ in range(int(rng.integers(1, 3))):
        w, h = float(rng.uniform(0.3, 0.9)), float(rng.uniform(0.3, 0.7))
        x0 = float(rng.uniform(0.2, max(0.3, length - w - 0.2)))
        if not free(x0, x0 + w):
            continue
        z0 = float(rng.uniform(1.2, min(1.7, H - h - 0.2)))
        f = 0.03
        frame_col = _col(rng, 20, 200)
        for lo, hi in (([x0, -0.025, z0], [x0 + f, 0.0, z0 + h]), ([x0 + w - f, -0.025, z0], [x0 + w, 0.0, z0 + h]),
                       ([x0 + f, -0.025, z0], [x0 + w - f, 0.0, z0 + f]), ([x0 + f, -0.025, z0 + h - f], [x0 + w - f, 0.0, z0 + h])):
            m.add_box(lo, hi, frame_col, None, T, material=WOOD)
        m.add_box([x0 + f, -0.012, z0 + f], [x0 + w - f, 0.0, z0 + h - f], _col(rng, 30, 240), None, T, material=GLOSSY)
        taken.append((x0, x0 + w))
    if rng.random() < 0.6:  # a radiator: vertical ribs (seams) and a valve knob
        w = float(rng.uniform(0.6, 1.2))
        x0 = float(rng.uniform(0.2, max(0.3, length - w - 0.2)))
        if free(x0, x0 + w):
            n = int(w / 0.05)
            for k in range(n):
                xa = x0 + k * w / n
                m.add_box([xa + 0.004, -0.08, 0.15], [xa + w / n - 0.004, -0.03, 0.75], (238, 238, 236), None, T, material=GLOSSY)
            m.add_cylinder(x0 + w + 0.04, 0.25, -0.1, -0.03, 0.025, (230, 230, 230), None, T, material=GLOSSY)
            taken.append((x0, x0 + w + 0.08))


CLUTTER = {"chair": chair_piece, "table": table_piece, "boxes": boxes_piece, "plant": plant_piece,
           "bookshelf": bookshelf_piece, "bed": bed_piece, "lamp": lamp_piece}
