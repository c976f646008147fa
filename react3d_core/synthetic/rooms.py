"""Rooms of free-standing furniture and appliances (kinds ``furniture``, ``appliances``, ``glass``,
``dark``), placed against walls and free in the room beside clutter.

Placement is rejection sampling on footprints (seeded): a piece may not overlap another piece, the
strip in front of an openable piece stays clear (chairs excepted: they stand at desks), and the zone
the camera walks in front of each piece (0.6-2.5 m ahead of it) holds nothing taller than 1.15 m, so
every front is seen from the hand-held path of :mod:`.camera_path`; pieces free in the room stand
0.8 m or more from the walls, turned up to +-25 degrees half the time.

- ``furniture``: an office (desk, filing cabinet, cabinet or sideboard, bookshelf, chair), a bedroom
  (wardrobe, nightstands, chest of drawers, bed) or a living room (sideboard, cabinets, table, chairs);
- ``appliances``: three or four of fridge, freezer (upright or chest), dishwasher, cooker, microwave
  on a cabinet and washing machine, with a piece of furniture half the time;
- ``glass``: a cupboard with solid doors below and glass-panel doors above, a kitchen run with
  glass-door wall cabinets, a vitrine, a sideboard with glass doors, a cooker (glass oven door), a
  microwave, a washing machine (glass porthole);
- ``dark``: a kitchen run with black / anthracite / dark wood fronts and two or three dark
  free-standing pieces (with ``depth_dropout="dark"`` most of their fronts drop out of the depth),
  and a light piece half the time.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from .appliances import (chest_freezer_piece, cooker_piece, dishwasher_piece, fridge_piece, microwave_stand_piece,
                         washing_machine_piece)
from .builder import MeshBuilder
from .clutter import CLUTTER, wall_decor
from .free_standing import (Piece, cabinet_piece, chest_piece, desk_piece, display_cupboard_piece,
                            filing_cabinet_piece, kitchen_run_piece, nightstand_piece, pick_finish, sideboard_piece,
                            vitrine_piece, wardrobe_piece)
from .fronts import FINISHES, PieceBuilder
from .furniture import WallFrame
from .procedural import SynthLayout, ViewRun, shell, wall_frames

FREE_KINDS = ("furniture", "appliances", "glass", "dark")
EYE_CLEAR = 1.15     # the camera (1.2-1.65 m) looks over anything lower
FRONT_CLEAR = 0.55   # free strip in front of an openable piece
ZONE = (0.6, 2.5)    # the camera walks this far in front of a piece
FREE_MARGIN = 0.8    # a piece free in the room stands this far from every wall


def _rect(fr: WallFrame, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """World xy corners (4, 2) of the wall-frame rectangle [x0,x1]x[y0,y1]."""
    T = fr.T
    p = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)
    return p @ T[:2, :2].T + T[:2, 3]


def _overlap(a: np.ndarray, b: np.ndarray) -> bool:
    area, _ = cv2.intersectConvexConvex(a.astype(np.float32), b.astype(np.float32))
    return area > 1e-6


@dataclass
class Planner:
    """Footprints placed so far and the zones that must stay clear (see module doc)."""

    W: float
    L: float
    rng: np.random.Generator
    feet: list[tuple[np.ndarray, float]] = field(default_factory=list)   # (footprint, height)
    fronts: list[np.ndarray] = field(default_factory=list)
    zones: list[np.ndarray] = field(default_factory=list)
    wall_taken: dict[int, list[tuple[float, float]]] = field(default_factory=dict)

    def inside(self, poly: np.ndarray, margin: float) -> bool:
        return bool((poly[:, 0] >= margin).all() and (poly[:, 0] <= self.W - margin).all()
                    and (poly[:, 1] >= margin).all() and (poly[:, 1] <= self.L - margin).all())

    def fits(self, piece: Piece, fr: WallFrame, margin: float, chair: bool = False) -> bool:
        foot = _rect(fr, -0.03, -0.03, piece.w + 0.03, piece.d + 0.03)
        if not self.inside(_rect(fr, 0.0, 0.0, piece.w, piece.d), margin):
            return False
        if any(_overlap(foot, f) for f, _ in self.feet):
            return False
        if not chair and any(_overlap(foot, z) for z in self.fronts):
            return False
        if piece.h + piece.extra_h > EYE_CLEAR and any(_overlap(foot, z) for z in self.zones):
            return False
        if piece.openable:
            front = _rect(fr, 0.0, -FRONT_CLEAR, piece.w, 0.0)
            zone = _rect(fr, -0.35, -ZONE[1], piece.w + 0.35, -ZONE[0])
            if not self.inside(front, 0.05) or not self.inside(_rect(fr, -0.35, -ZONE[0] - 0.4, piece.w + 0.35, -ZONE[0]), 0.15):
                return False
            if any(_overlap(front, f) for f, _ in self.feet):
                return False
            if any(_overlap(zone, f) for f, h in self.feet if h > EYE_CLEAR):
                return False
            if self.free_depth(fr, piece.d) - piece.d < 1.5:  # room for the camera in front
                return False
        return True

    def take(self, piece: Piece, fr: WallFrame) -> None:
        self.feet.append((_rect(fr, 0.0, 0.0, piece.w, piece.d), piece.h + piece.extra_h))
        if piece.openable:
            self.fronts.append(_rect(fr, 0.0, -FRONT_CLEAR, piece.w, 0.0))
            self.zones.append(_rect(fr, -0.35, -ZONE[1], piece.w + 0.35, -ZONE[0]))

    def at_wall(self, piece: Piece, tries: int = 40, walls: tuple[int, ...] = (0, 1, 2, 3)) -> tuple[WallFrame, int] | None:
        """A spot against one of ``walls`` (frame origin at the piece's front-left-bottom corner)."""
        frames = wall_frames(self.W, self.L)
        for _ in range(tries):
            k = int(walls[int(self.rng.integers(len(walls)))])
            wf, length = frames[k]
            if length < piece.w + 0.3:
                continue
            x = float(self.rng.uniform(0.1, length - piece.w - 0.1))
            fr = wf.shifted(x, -(piece.d + piece.wall_gap))
            if self.fits(piece, fr, -1e-6):
                self.take(piece, fr)
                self.wall_taken.setdefault(k, []).append((x, x + piece.w))
                return fr, k
        return None

    def free(self, piece: Piece, tries: int = 60) -> WallFrame | None:
        """A spot free in the room, facing along a wall direction turned by up to 25 degrees half the time."""
        for _ in range(tries):
            th = float(self.rng.choice([0.0, -np.pi / 2, np.pi, np.pi / 2]))
            if self.rng.random() < 0.5:
                th += float(np.radians(self.rng.uniform(-25, 25)))
            c = np.array([self.rng.uniform(FREE_MARGIN, self.W - FREE_MARGIN), self.rng.uniform(FREE_MARGIN, self.L - FREE_MARGIN)])
            R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
            o = c - R @ np.array([piece.w / 2, piece.d / 2])
            fr = WallFrame(np.array([o[0], o[1], 0.0]), th)
            if self.fits(piece, fr, FREE_MARGIN if piece.openable else 0.05):
                self.take(piece, fr)
                return fr
        return None

    def free_depth(self, fr: WallFrame, d: float) -> float:
        """Distance from the piece's back (y = d) along its front direction to the room's walls."""
        T = fr.T
        f = T[:2, :2] @ np.array([0.0, -1.0])
        p = T[:2, :2] @ np.array([0.0, d]) + T[:2, 3]
        ts = []
        for k, lim in ((0, 0.0), (0, self.W), (1, 0.0), (1, self.L)):
            if abs(f[k]) > 1e-9:
                t = (lim - p[k]) / f[k]
                if t > 0:
                    ts.append(t)
        return float(min(ts))


def _place(b: PieceBuilder, plan: Planner, piece: Piece, runs: list[ViewRun], free: bool) -> WallFrame | None:
    """Place and build one piece (free in the room or against a wall; falls back to the other)."""
    fr = plan.free(piece) if free and piece.free_ok else None
    if fr is None:
        got = plan.at_wall(piece)
        fr = got[0] if got is not None else None
    if fr is None and piece.free_ok and not free:
        fr = plan.free(piece)
    if fr is None:
        return None
    piece.build(fr)
    if piece.openable:
        back = fr.shifted(0.0, piece.d)
        runs.append(ViewRun(back, 0.0, piece.w, piece.z_fronts[0], piece.z_fronts[1], piece.d,
                            free_depth=plan.free_depth(fr, piece.d)))
    return fr


FURNITURE = {"desk": desk_piece, "nightstand": nightstand_piece, "chest": chest_piece, "filing_cabinet": filing_cabinet_piece,
             "cabinet": cabinet_piece, "wardrobe": wardrobe_piece, "sideboard": sideboard_piece}
APPLIANCES = {"fridge": fridge_piece, "freezer": chest_freezer_piece, "dishwasher": dishwasher_piece, "cooker": cooker_piece,
              "microwave": microwave_stand_piece, "washing_machine": washing_machine_piece}


def _pieces(kind: str, b: PieceBuilder, rng: np.random.Generator) -> tuple[list[tuple[Piece, bool]], list[str]]:
    """(piece, free in the room?) to place, most constrained first, and the clutter to add."""
    out: list[tuple[Piece, bool]] = []
    if kind == "furniture":
        room = ["office", "bedroom", "living"][int(rng.integers(3))]
        if room == "office":
            names = ["desk", "filing_cabinet", ["cabinet", "sideboard"][int(rng.integers(2))]] + (["chest"] if rng.random() < 0.4 else [])
            clutter = ["chair", "bookshelf", "plant"] + (["boxes"] if rng.random() < 0.6 else [])
        elif room == "bedroom":
            names = ["wardrobe", "nightstand", "chest"] + (["nightstand"] if rng.random() < 0.6 else []) + (["desk"] if rng.random() < 0.3 else [])
            clutter = ["bed", "plant"] + (["lamp"] if rng.random() < 0.5 else [])
        else:
            names = ["sideboard", "cabinet"] + (["chest"] if rng.random() < 0.5 else ["nightstand"]) + (["cabinet"] if rng.random() < 0.4 else [])
            clutter = ["table", "chair", "chair", "plant"] + (["bookshelf"] if rng.random() < 0.5 else [])
        for nm in names:
            p = FURNITURE[nm](b, rng)
            out.append((p, bool(p.free_ok and rng.random() < 0.45)))
        if not any(f for _, f in out):  # at least one piece tries to stand free
            k = next((i for i, (p, _) in enumerate(out) if p.free_ok), None)
            if k is not None:
                out[k] = (out[k][0], True)
    elif kind == "appliances":
        names = list(rng.choice(list(APPLIANCES), size=int(rng.integers(3, 5)), replace=False))
        for nm in names:
            out.append((APPLIANCES[nm](b, rng), bool(rng.random() < 0.25)))
        if rng.random() < 0.5:
            out.append((FURNITURE[["cabinet", "sideboard", "chest"][int(rng.integers(3))]](b, rng), bool(rng.random() < 0.5)))
        clutter = ["table", "chair", "boxes", "plant"][: int(rng.integers(2, 5))]
    elif kind == "glass":
        first = [display_cupboard_piece, kitchen_run_piece][int(rng.integers(2))]
        out.append((first(b, rng, glass_p=0.8) if first is kitchen_run_piece else first(b, rng), False))
        others = [vitrine_piece, cooker_piece, microwave_stand_piece, washing_machine_piece, sideboard_piece, display_cupboard_piece]
        for k in rng.choice(len(others), size=int(rng.integers(2, 4)), replace=False):
            fn = others[int(k)]
            p = fn(b, rng, glass_p=0.6) if fn is sideboard_piece else fn(b, rng)
            out.append((p, bool(p.free_ok and rng.random() < 0.3)))
        clutter = ["table", "chair", "plant"][: int(rng.integers(1, 4))]
    elif kind == "dark":
        out.append((kitchen_run_piece(b, rng, pick_finish(rng, dark=True), glass_p=0.0, max_units=5), False))
        names = list(rng.choice(["sideboard", "wardrobe", "desk", "filing_cabinet", "chest", "cabinet"], size=int(rng.integers(2, 4)), replace=False))
        for nm in names:
            fin = FINISHES["black_matte"] if nm == "filing_cabinet" and rng.random() < 0.5 else pick_finish(rng, dark=True)
            p = FURNITURE[nm](b, rng, fin)
            out.append((p, bool(p.free_ok and rng.random() < 0.4)))
        if rng.random() < 0.5:  # a light piece for contrast
            out.append((FURNITURE[["chest", "cabinet", "nightstand"][int(rng.integers(3))]](b, rng, pick_finish(rng, dark=False)), False))
        clutter = ["chair", "plant", "boxes"][: int(rng.integers(1, 4))]
    else:
        raise ValueError(kind)
    # tall pieces against walls first (they constrain the most), then the rest
    out.sort(key=lambda t: (t[1], -t[0].h))
    return out, clutter


def build_free_room(seed: int, kind: str, edge: float = 0.03) -> SynthLayout:
    """A seeded room of free-standing pieces of ``kind`` (see module doc)."""
    if kind not in FREE_KINDS:
        raise ValueError(f"unknown free-standing kind {kind!r}; choose from {', '.join(FREE_KINDS)}")
    rng = np.random.default_rng([seed, FREE_KINDS.index(kind), 40])
    W, L, H = float(rng.uniform(4.0, 5.4)), float(rng.uniform(4.4, 6.0)), float(rng.uniform(2.5, 2.9))
    m = MeshBuilder(edge=edge, seed=seed)
    b = PieceBuilder(m, rng)
    shell(m, rng, W, L, H, None)
    plan = Planner(W, L, rng)
    runs: list[ViewRun] = []
    pieces, clutter = _pieces(kind, b, rng)
    placed: list[tuple[Piece, WallFrame]] = []
    for piece, free in pieces:
        fr = _place(b, plan, piece, runs, free)
        if fr is not None:
            placed.append((piece, fr))
    for name in clutter:
        piece = CLUTTER[name](b, rng)
        fr = None
        if name == "chair":  # at a desk or a table when there is one
            hosts = [(p, f) for p, f in placed if p.name in ("desk", "table")]
            if hosts:
                hp, hf = hosts[int(rng.integers(len(hosts)))]
                c = hf.T[:2, :2] @ np.array([hp.w / 2, -0.35]) + hf.T[:2, 3]
                for _ in range(20):
                    cand = WallFrame(np.zeros(3), hf.theta + np.pi + float(rng.uniform(-0.4, 0.4)))
                    R = cand.T[:2, :2]
                    o = c + rng.uniform(-0.25, 0.25, 2) - R @ np.array([piece.w / 2, piece.d / 2])
                    cand = WallFrame(np.array([o[0], o[1], 0.0]), cand.theta)
                    if plan.fits(piece, cand, 0.05, chair=True):
                        plan.take(piece, cand)
                        fr = cand
                        break
        if fr is None and name == "bed":
            got = plan.at_wall(piece)
            fr = got[0] if got else None
        if fr is None and name != "bed":
            fr = plan.free(piece, tries=30)
        if fr is not None:
            piece.build(fr)
            placed.append((piece, fr))
    for k, (wf, length) in enumerate(wall_frames(W, L)):
        wall_decor(b, wf, length, H, rng, plan.wall_taken.setdefault(k, []))
    if not runs:
        raise RuntimeError(f"seed {seed}: no openable piece could be placed in the {kind} room")
    mesh, keys, key_ids = m.build()
    extra = {"pieces": [p.name for p, _ in placed if p.openable], "clutter": [p.name for p, _ in placed if not p.openable]}
    return SynthLayout(mesh, keys, key_ids, b.parts, b.statics, runs, (W, L, H), kind, extra=extra,
                       face_materials=m.materials(), face_colors=m.base_colors(), gt_boxes=True)
