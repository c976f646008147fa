"""Free-standing appliances with doors: fridges, freezers (upright and chest), dishwashers, cookers
(a glass oven door), microwaves (a glass door window) and washing machines (a round porthole door and
a detergent drawer).

Same contract as :mod:`.free_standing`: each ``*_piece`` returns a :class:`~.free_standing.Piece`
built at a frame whose origin is its front-left-bottom corner. Appliance doors are thick (4-6 cm),
bodies are hollow with a liner (white plastic, dark enamel, steel drum), handles are long bars,
edge grips or none, and the cooker and washing machine carry static knobs and panels that look like
handles and seams but do not move.
"""

from __future__ import annotations

import numpy as np

from .free_standing import Piece
from .fronts import APPLIANCE, FINISHES, SMOKED_TINT, Y_UP, Finish, PieceBuilder
from .furniture import WallFrame
from .materials import GLOSSY, METAL

WHITE_LINER = (235, 238, 240)
ENAMEL = (48, 48, 52)
DRUM = (170, 172, 176)


def pick_appliance(rng: np.random.Generator) -> Finish:
    return FINISHES[APPLIANCE[int(rng.integers(len(APPLIANCE)))]]


def _knobs(b: PieceBuilder, fr: WallFrame, xs: list[float], z: float, y: float, fin: Finish) -> None:
    """Round control knobs standing out of a panel at y (static: they look like handles)."""
    for x in xs:
        b.mesh.add_cylinder(x, z, y - 0.025, y, 0.02, fin.handle, None, fr.T, material=METAL)


def fridge_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A fridge: one tall door, a fridge-over-freezer pair of doors, a fridge door over 2-3 freezer
    drawers, or a side-by-side pair; long vertical bars or edge grips."""
    fin = fin or pick_appliance(rng)
    style = ["single", "combi", "combi_drawers", "side_by_side"][int(rng.choice(4, p=[0.25, 0.35, 0.25, 0.15]))]
    W = float(rng.uniform(0.85, 0.92)) if style == "side_by_side" else float(rng.uniform(0.55, 0.7))
    D, H = float(rng.uniform(0.62, 0.7)), float(rng.uniform(1.7, 1.9) if style != "single" else rng.uniform(0.85, 1.85))
    hinge = "door_left" if rng.random() < 0.5 else "door_right"
    handle = "long" if rng.random() < 0.7 else "edge"
    thick = float(rng.uniform(0.045, 0.06))
    z0 = 0.04

    def build(fr: WallFrame) -> None:
        name = b._name("fridge")
        Hb = H - z0
        zs = []
        if style == "combi":
            zs = [z0 + 0.36 * Hb]
        elif style == "combi_drawers":
            k = int(rng.integers(2, 4))
            zs = [z0 + 0.36 * Hb * (i + 1) / k for i in range(k)]
        shelves = [(0.02, W - 0.02, z) for z in zs]
        b.body(fr, name, W, D - thick, z0, Hb, fin, shelves, liner=WHITE_LINER, t=0.04, plinth=z0)
        depth = D - thick - 0.08
        g, yb = 0.003, 0.0
        if style == "side_by_side":
            xm = W / 2
            for k, (a, c) in (("door_left", (g, xm - g)), ("door_right", (xm + g, W - g))):
                hx = c - 0.04 if k == "door_left" else a + 0.04
                b.panel_front(fr, k, a, c, z0 + g, H - g, fin, handle, name, depth, "fridge", thickness=thick,
                              handle_length=0.5 * Hb, handle_at=(hx, z0 + 0.6 * Hb), y_back=yb)
            return
        bounds = [z0] + zs + [H]
        for i, (za, zb) in enumerate(zip(bounds[:-1], bounds[1:])):
            top = i == len(bounds) - 2
            if style == "combi_drawers" and not top:
                b.panel_front(fr, "drawer", g, W - g, za + g, zb - g, fin, "long" if handle == "long" else "edge", name,
                              depth, "freezer", thickness=thick, handle_length=0.6 * W, y_back=yb)
                continue
            hx = W - 0.04 if hinge == "door_left" else 0.04
            hz = za + 0.25 * (zb - za) if top and bounds[0] != za else (zb - 0.2 * (zb - za) if not top else za + 0.45 * (zb - za))
            b.panel_front(fr, hinge, g, W - g, za + g, zb - g, fin, handle, name, depth, "fridge" if top else "freezer",
                          thickness=thick, handle_length=min(0.45, 0.4 * (zb - za)), handle_at=(hx, hz), y_back=yb)

    return Piece("fridge", W, D, H, build, (z0, H), wall_gap=0.04, tags=["appliance"])


def chest_freezer_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A chest freezer: an open-top body (white liner) under a lid hinged at the back."""
    fin = fin or FINISHES["appliance_white"]
    W, D, H = float(rng.uniform(0.8, 1.3)), float(rng.uniform(0.6, 0.7)), float(rng.uniform(0.82, 0.88))
    t_lid = 0.06

    def build(fr: WallFrame) -> None:
        name = b._name("freezer")
        b.body(fr, name, W, D, 0.03, H - t_lid - 0.03, fin, liner=WHITE_LINER, t=0.05, open_top=True, plinth=0.03)
        b.lid(fr, W, D, H - t_lid, fin, name, H - t_lid - 0.1, "freezer", thickness=t_lid)

    return Piece("chest_freezer", W, D, H, build, (0.03, H), wall_gap=0.05, tags=["appliance"])


def dishwasher_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A free-standing dishwasher: a bottom-hinged door with a control strip at its top, a worktop lid."""
    fin = fin or pick_appliance(rng)
    W = 0.45 if rng.random() < 0.3 else 0.6
    D, H = float(rng.uniform(0.58, 0.62)), float(rng.uniform(0.84, 0.86))
    handle = ["long", "edge", "none"][int(rng.integers(3))]
    z0 = float(rng.uniform(0.08, 0.11))

    def build(fr: WallFrame) -> None:
        name = b._name("dishwasher")
        b.body(fr, name, W, D - 0.04, z0, H - z0 - 0.02, fin, liner=DRUM, t=0.03, plinth=z0)
        b.static_box(fr, [0.0, -0.04, H - 0.02], [W, D, H], fin.body, "dishwasher_top", material=fin.body_mat)
        spec = b.panel_front(fr, "drop", 0.003, W - 0.003, z0 + 0.003, H - 0.025, fin, handle, name, D - 0.12, "dishwasher",
                             thickness=0.04, handle_length=0.6 * W, handle_at=(W / 2, H - 0.1), y_back=0.0)
        # a dark control strip on the door's top edge (part of the door)
        b.mesh.add_box([0.02, -0.041, H - 0.075], [W - 0.02, -0.04, H - 0.035], (40, 40, 44), spec.key, fr.T, material=GLOSSY)

    return Piece("dishwasher", W, D, H, build, (z0, H), tags=["appliance"])


def cooker_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None, glass: bool = True) -> Piece:
    """A free-standing cooker: a storage drawer at the bottom (half the time), an oven with a
    bottom-hinged glass door (dark enamel inside), a control panel with knobs and a hob on top."""
    fin = fin or pick_appliance(rng)
    W, D, H = float(rng.choice([0.5, 0.6])), float(rng.uniform(0.58, 0.62)), float(rng.uniform(0.85, 0.9))
    drawer = bool(rng.random() < 0.5)
    z0 = 0.03

    def build(fr: WallFrame) -> None:
        name = b._name("oven")
        zd = z0 + (0.14 if drawer else 0.0)
        zt = H - 0.13  # top of the oven door; control panel above it
        shelves = [(0.02, W - 0.02, zd)] if drawer else []
        b.body(fr, name, W, D - 0.05, z0, H - z0 - 0.03, fin, shelves, liner=ENAMEL, t=0.03, plinth=z0)
        depth = D - 0.15
        if drawer:
            b.panel_front(fr, "drawer", 0.003, W - 0.003, z0 + 0.003, zd - 0.003, fin, "long", name, depth, "oven",
                          thickness=0.03, handle_length=0.6 * W, y_back=0.0)
        b.panel_front(fr, "drop", 0.003, W - 0.003, zd + 0.003, zt - 0.003, fin, "long", name, depth, "oven",
                      thickness=0.045, glass=(0.08, 0.08, 0.08, 0.12) if glass else None, tint=SMOKED_TINT,
                      handle_length=0.7 * W, handle_at=(W / 2, zt - 0.05), y_back=0.0)
        # control panel: a static strip with knobs, and the hob
        b.static_box(fr, [0.0, -0.02, zt], [W, 0.02, H - 0.03], fin.body, "oven_panel", material=fin.body_mat)
        _knobs(b, fr, list(np.linspace(0.1, W - 0.1, 4)), 0.5 * (zt + H - 0.03), -0.02, fin)
        b.static_box(fr, [0.0, -0.02, H - 0.03], [W, D, H], (25, 25, 28), "hob", material=GLOSSY)
        for cx, cy in ((0.3 * W, 0.25 * D), (0.7 * W, 0.25 * D), (0.3 * W, 0.7 * D), (0.7 * W, 0.7 * D)):
            b.mesh.add_cylinder(cx, -cy, H, H + 0.004, 0.08, (60, 60, 62), None, fr.T @ Y_UP, r_in=0.06, material=METAL)

    return Piece("cooker", W, D, H, build, (z0, H), tags=["appliance", "glass"])


def microwave(b: PieceBuilder, fr: WallFrame, rng: np.random.Generator, z: float, fin: Finish | None = None) -> tuple[float, float]:
    """A microwave standing at height ``z`` at the frame's origin: a left-hinged door with a dark glass
    window, a control panel with buttons on the right. Returns its width and height."""
    fin = fin or pick_appliance(rng)
    W, D, H = float(rng.uniform(0.45, 0.52)), float(rng.uniform(0.34, 0.4)), float(rng.uniform(0.26, 0.3))
    name = b._name("microwave")
    wd = 0.72 * W
    b.body(fr, name, W, D, z, H, fin, [], [(wd, z, z + H)], liner=(150, 150, 150), t=0.02)
    b.static_box(fr, [wd + 0.003, -0.02, z + 0.003], [W - 0.003, 0.0, z + H - 0.003], (40, 40, 44), "microwave_panel",
                 material=GLOSSY)
    for k in range(3):
        b.mesh.add_box([wd + 0.03, -0.026, z + H - 0.06 - 0.05 * k], [W - 0.03, -0.02, z + H - 0.04 - 0.05 * k],
                       (150, 150, 155), None, fr.T, material=METAL)
    handle = "long" if rng.random() < 0.5 else "none"
    b.panel_front(fr, "door_left", 0.003, wd - 0.003, z + 0.003, z + H - 0.003, fin, handle, name, D - 0.05, "microwave",
                  thickness=0.02, glass=(0.06, 0.05, 0.05, 0.05), tint=SMOKED_TINT, handle_length=0.8 * H,
                  handle_at=(wd - 0.03, z + H / 2), y_back=0.0)
    return W, H


def microwave_stand_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A low cabinet (two doors or a drawer over a door) with a microwave standing on it."""
    from .free_standing import pick_finish, pick_handle

    fin = fin or pick_finish(rng)
    handle = pick_handle(rng)
    W, D, H = float(rng.uniform(0.6, 0.9)), float(rng.uniform(0.45, 0.55)), float(rng.uniform(0.8, 0.92))
    cells = [(1.0, "door2")] if W >= 0.7 else [(0.75, "door_left"), (0.25, "drawer")]
    mw_fin = pick_appliance(rng)

    def build(fr: WallFrame) -> None:
        b.grid(fr, "cabinet", W, D, 0.06, H - 0.06 - 0.03, [(1.0, cells)], fin, handle, plinth=0.06)
        b.static_box(fr, [-0.01, -0.01, H - 0.03], [W + 0.01, D, H], fin.body, "cabinet_top", material=fin.body_mat)
        microwave(b, fr.shifted(float(rng.uniform(0.02, max(0.03, W - 0.55))), 0.04), rng, H, mw_fin)

    return Piece("microwave_stand", W, D, H, build, (0.06, H + 0.3), extra_h=0.3, tags=["appliance", "glass"])


def washing_machine_piece(b: PieceBuilder, rng: np.random.Generator, fin: Finish | None = None) -> Piece:
    """A front-loading washing machine: a round porthole door (ring and glass bowl, hinged on the left)
    over a square opening into a steel drum, a detergent drawer top left, a programme knob top right."""
    fin = fin or FINISHES["appliance_white" if rng.random() < 0.75 else "appliance_steel"]
    W, D, H = 0.6, float(rng.uniform(0.55, 0.62)), float(rng.uniform(0.84, 0.86))
    r = float(rng.uniform(0.2, 0.24))
    z0 = 0.02

    def build(fr: WallFrame) -> None:
        name = b._name("washing_machine")
        zc, cx = z0 + 0.12 + r + 0.03, W / 2
        b.body(fr, name, W, D, z0, H - z0, fin, [(0.02, W - 0.02, H - 0.16)], liner=DRUM, t=0.02, plinth=z0)
        # the front panel: a plate with a square opening behind the door (the drum is behind it)
        s = 1.3 * r / 2
        fp, T = 0.02, fr.T
        for lo, hi in (([0.0, -fp, z0], [W, 0.0, zc - s]), ([0.0, -fp, zc + s], [W, 0.0, H - 0.16]),
                       ([0.0, -fp, zc - s], [cx - s, 0.0, zc + s]), ([cx + s, -fp, zc - s], [W, 0.0, zc + s])):
            b.mesh.add_box(lo, hi, fin.body, name, T, material=fin.body_mat)
        b.round_door(fr, cx, zc, r, fin, name, D - 0.1, "washing_machine", y_back=-fp)
        # top panel: detergent drawer (left), knob (right), the rest static
        zt0 = H - 0.16
        b.static_box(fr, [0.2, -fp, zt0], [W, 0.0, H - 0.02], fin.body, "washing_machine_panel", material=fin.body_mat)
        b.panel_front(fr, "drawer", 0.003, 0.197, zt0 + 0.003, H - 0.023, fin, "edge", name, 0.35, "washing_machine",
                      thickness=0.02, y_back=-fp)
        _knobs(b, fr, [W - 0.12], zt0 + 0.07, -fp, fin)
        b.static_box(fr, [0.0, -fp, H - 0.02], [W, D, H], fin.body, "washing_machine_top", material=fin.body_mat)

    return Piece("washing_machine", W, D, H, build, (z0, H), wall_gap=0.03, tags=["appliance", "glass"])
