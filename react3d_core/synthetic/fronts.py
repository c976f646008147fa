"""Fronts, handles, glass panels and hollow bodies for free-standing furniture and appliances.

:class:`PieceBuilder` extends the wall-run :class:`~.furniture.Builder` (same wall-frame convention:
x along the front left to right seen from the room, +y into the piece, z up, front at y = 0) with
what free-standing pieces need: a body on legs or a plinth with vertical dividers (columns of cells),
thick appliance doors, handles of several styles (bars, long appliance bars, knobs, edge pulls, none),
glass-panel doors (a frame around a see-through pane: one part), round porthole doors and top lids.
Every movable front is a :class:`~.furniture.PartSpec` with its world joint; q = 0 is closed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .furniture import BOARD, FRONT, GAP, PROUD, Builder, PartSpec, WallFrame
from .materials import GLASS, GLOSSY, MATTE, METAL, WOOD

RGB = tuple[int, int, int]
GLASS_TINT: RGB = (222, 236, 232)   # clear glass, faintly green
SMOKED_TINT: RGB = (120, 126, 128)  # oven / microwave windows


@dataclass(frozen=True)
class Finish:
    """The look of one piece: fronts, body and handles (colour and material); ``dark``: a low-albedo
    finish that a depth sensor struggles with."""

    name: str
    front: RGB
    front_mat: int
    body: RGB
    body_mat: int
    handle: RGB
    handle_mat: int = METAL
    dark: bool = False


FINISHES: dict[str, Finish] = {f.name: f for f in (
    Finish("oak", (172, 136, 96), WOOD, (162, 128, 90), WOOD, (55, 55, 58)),
    Finish("beech", (205, 170, 125), WOOD, (195, 162, 120), WOOD, (200, 200, 205)),
    Finish("walnut", (110, 76, 50), WOOD, (100, 70, 46), WOOD, (205, 205, 210)),
    Finish("white_matte", (236, 234, 228), MATTE, (228, 226, 220), MATTE, (150, 150, 155)),
    Finish("white_gloss", (242, 242, 240), GLOSSY, (232, 232, 230), MATTE, (60, 60, 64)),
    Finish("light_grey", (190, 192, 190), MATTE, (200, 200, 198), MATTE, (70, 70, 74)),
    Finish("sage", (128, 146, 120), MATTE, (220, 216, 205), MATTE, (185, 160, 90)),
    Finish("blue", (70, 96, 130), GLOSSY, (226, 226, 222), MATTE, (210, 210, 212)),
    Finish("steel", (176, 179, 182), METAL, (168, 171, 174), METAL, (90, 90, 94), METAL),
    Finish("appliance_white", (243, 243, 241), GLOSSY, (238, 238, 236), GLOSSY, (185, 185, 190)),
    Finish("appliance_steel", (186, 188, 190), METAL, (176, 178, 180), METAL, (70, 70, 72)),
    Finish("appliance_black", (32, 32, 35), GLOSSY, (36, 36, 39), GLOSSY, (175, 175, 180), METAL, True),
    Finish("black_matte", (28, 28, 30), MATTE, (32, 32, 34), MATTE, (185, 185, 190), METAL, True),
    Finish("black_gloss", (20, 20, 23), GLOSSY, (30, 30, 32), MATTE, (195, 195, 200), METAL, True),
    Finish("anthracite", (55, 57, 61), MATTE, (60, 62, 66), MATTE, (200, 200, 205), METAL, True),
    Finish("dark_walnut", (64, 43, 30), WOOD, (58, 40, 28), WOOD, (190, 170, 110), METAL, True),
    Finish("dark_green", (34, 52, 42), GLOSSY, (40, 56, 46), MATTE, (190, 190, 195), METAL, True),
    Finish("navy", (30, 38, 58), MATTE, (36, 44, 64), MATTE, (200, 200, 205), METAL, True),
)}
LIGHT = ("oak", "beech", "walnut", "white_matte", "white_gloss", "light_grey", "sage", "blue")
DARK = ("black_matte", "black_gloss", "anthracite", "dark_walnut", "dark_green", "navy")
APPLIANCE = ("appliance_white", "appliance_white", "appliance_steel", "appliance_black")
HANDLE_STYLES = ("bar", "bar", "knob", "edge", "none")


@dataclass
class PieceBuilder(Builder):
    """A :class:`~.furniture.Builder` with the fronts and bodies of free-standing pieces."""

    # -- handles -------------------------------------------------------------------------------
    def handle(self, T: np.ndarray, key: str, style: str, fin: Finish, x0: float, x1: float, z0: float, z1: float,
               y_face: float, horiz: bool, hx: float, hz: float, length: float | None = None) -> str | None:
        """A handle on the front face at y = ``y_face`` (room side is -y); returns its key or None.

        ``bar``: a bar on two posts (12-22 cm); ``long``: an appliance bar (``length``); ``knob``: a
        small square knob; ``edge``: a thin pull along the top edge of a drawer or the opening edge of
        a door; ``none``: push to open. ``(hx, hz)`` is where a bar or knob sits, ``horiz`` its run."""
        if style == "none":
            return None
        hkey = key + ".handle"
        col, mat = fin.handle, fin.handle_mat
        if style in ("bar", "long"):
            w, h = x1 - x0, z1 - z0
            ln = length if length is not None else min(0.8 * (w if horiz else h), float(self.rng.choice([0.12, 0.16, 0.22])))
            bar, proud, post = 0.012, 0.03, 0.01
            if horiz:
                self.mesh.add_box([hx - ln / 2, y_face - proud, hz - bar / 2], [hx + ln / 2, y_face - proud + bar, hz + bar / 2],
                                  col, hkey, T, material=mat)
                for px in (hx - ln / 2 + 0.01, hx + ln / 2 - 0.01 - post):
                    self.mesh.add_box([px, y_face - proud + bar, hz - post / 2], [px + post, y_face, hz + post / 2], col, hkey, T,
                                      skip=((1, 1),), material=mat)
            else:
                self.mesh.add_box([hx - bar / 2, y_face - proud, hz - ln / 2], [hx + bar / 2, y_face - proud + bar, hz + ln / 2],
                                  col, hkey, T, material=mat)
                for pz in (hz - ln / 2 + 0.01, hz + ln / 2 - 0.01 - post):
                    self.mesh.add_box([hx - post / 2, y_face - proud + bar, pz], [hx + post / 2, y_face, pz + post], col, hkey, T,
                                      skip=((1, 1),), material=mat)
        elif style == "knob":
            s = 0.03
            self.mesh.add_box([hx - s / 2, y_face - 0.025, hz - s / 2], [hx + s / 2, y_face, hz + s / 2], col, hkey, T,
                              skip=((1, 1),), material=mat)
        elif style == "edge":
            t = 0.015
            if horiz:  # a lip along the top edge, 60 % of the width
                w = 0.6 * (x1 - x0)
                xm = 0.5 * (x0 + x1)
                self.mesh.add_box([xm - w / 2, y_face - 0.02, z1 - t], [xm + w / 2, y_face, z1], col, hkey, T, skip=((1, 1),),
                                  material=mat)
            else:  # a strip along the opening edge (hx says which), 40 % of the height
                h = min(0.4 * (z1 - z0), 0.6)
                xe = x1 - t if hx > 0.5 * (x0 + x1) else x0
                self.mesh.add_box([xe, y_face - 0.02, hz - h / 2], [xe + t, y_face, hz + h / 2], col, hkey, T, skip=((1, 1),),
                                  material=mat)
        else:
            raise ValueError(f"unknown handle style {style!r}")
        return hkey

    # -- fronts --------------------------------------------------------------------------------
    def _joint(self, frame: WallFrame, kind: str, x0: float, x1: float, z0: float, z1: float, ym: float,
               depth: float | None) -> tuple[object, str]:
        """World joint of a front over [x0,x1]x[z0,z1] (mid-thickness ``ym``) and the GT kind word."""
        xm, zm = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
        if kind == "door_left":
            return self._world_joint(frame, "revolute", [0, 0, -1], [x0, ym, zm], float(np.radians(self.rng.uniform(95, 115)))), "door"
        if kind == "door_right":
            return self._world_joint(frame, "revolute", [0, 0, 1], [x1, ym, zm], float(np.radians(self.rng.uniform(95, 115)))), "door"
        if kind == "flap":
            return self._world_joint(frame, "revolute", [-1, 0, 0], [xm, ym, z1], float(np.radians(self.rng.uniform(75, 90)))), "flap"
        if kind == "drop":
            return self._world_joint(frame, "revolute", [1, 0, 0], [xm, ym, z0], float(np.radians(self.rng.uniform(80, 90)))), "drop"
        if kind == "drawer":
            travel = 0.85 * depth if depth else 0.3
            return self._world_joint(frame, "prismatic", [0, -1, 0], [xm, ym, zm], float(travel)), "drawer"
        raise ValueError(f"unknown front kind {kind!r}")

    def panel_front(self, frame: WallFrame, kind: str, x0: float, x1: float, z0: float, z1: float, fin: Finish,
                    handle: str, carcass_key: str | None, depth: float | None, label_base: str,
                    thickness: float = FRONT, glass: tuple[float, float, float, float] | None = None,
                    tint: RGB = GLASS_TINT, muntins: int = 0, handle_length: float | None = None,
                    handle_at: tuple[float, float] | None = None, y_back: float = -PROUD) -> PartSpec:
        """A front over [x0,x1]x[z0,z1] whose back face is at y = ``y_back``, with its joint and handle.

        ``glass`` = frame widths (left, right, bottom, top): the front is a frame around a glass pane
        (4 mm, in the middle of the frame's thickness; ``muntins`` glazing bars across it), and frame
        and pane are one part. ``handle_at`` overrides where a bar or knob sits."""
        T = frame.T
        key = self._name((carcass_key or label_base) + "_f")
        y0, y1 = y_back - thickness, y_back
        if glass is None:
            self.mesh.add_box([x0, y0, z0], [x1, y1, z1], fin.front, key, T, material=fin.front_mat)
        else:
            fl, fr, fb, ft = glass
            for lo, hi in (([x0, y0, z0], [x0 + fl, y1, z1]), ([x1 - fr, y0, z0], [x1, y1, z1]),
                           ([x0 + fl, y0, z0], [x1 - fr, y1, z0 + fb]), ([x0 + fl, y0, z1 - ft], [x1 - fr, y1, z1])):
                self.mesh.add_box(lo, hi, fin.front, key, T, material=fin.front_mat)
            gy = 0.5 * (y0 + y1)
            self.mesh.add_box([x0 + fl - 0.004, gy - 0.002, z0 + fb - 0.004], [x1 - fr + 0.004, gy + 0.002, z1 - ft + 0.004],
                              tint, key, T, material=GLASS)
            for k in range(muntins):  # horizontal glazing bars
                zc = z0 + fb + (k + 1) * (z1 - ft - z0 - fb) / (muntins + 1)
                self.mesh.add_box([x0 + fl, gy - 0.006, zc - 0.01], [x1 - fr, gy + 0.006, zc + 0.01], fin.front, key, T,
                                  material=fin.front_mat)
        art, word = self._joint(frame, kind, x0, x1, z0, z1, 0.5 * (y0 + y1), depth)
        h = z1 - z0
        xm, zm = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
        if kind == "door_left":
            hx, hz, horiz = x1 - 0.045, (z1 - 0.18 * h if h > 0.5 else zm), False
        elif kind == "door_right":
            hx, hz, horiz = x0 + 0.045, (z1 - 0.18 * h if h > 0.5 else zm), False
        elif kind == "flap":
            hx, hz, horiz = xm, z0 + 0.04, True
        elif kind == "drop":
            hx, hz, horiz = xm, z1 - 0.05, True
        else:
            hx, hz, horiz = xm, (z1 - min(0.06, 0.3 * h) if h > 0.2 else zm), True
        if handle_at is not None:
            hx, hz = handle_at
        hkey = self.handle(T, key, handle, fin, x0, x1, z0, z1, y0, horiz, hx, hz, handle_length)
        spec = PartSpec(key, f"{label_base}.{word}_{len(self.parts) + 1}", word, art, carcass_key, hkey, depth)  # type: ignore[arg-type]
        self.parts.append(spec)
        return spec

    def round_door(self, frame: WallFrame, cx: float, cz: float, r: float, fin: Finish, carcass_key: str, depth: float,
                   label_base: str, y_back: float, thickness: float = 0.06) -> PartSpec:
        """A porthole door (washing machine, dryer): a ring around a glass bowl, hinged on its left edge,
        with a grip on the right; ring, glass and grip are one part."""
        T = frame.T
        key = self._name(carcass_key + "_f")
        y0, y1 = y_back - thickness, y_back
        r_in = 0.72 * r
        self.mesh.add_cylinder(cx, cz, y0, y1, r, fin.front, key, T, r_in=r_in, material=fin.front_mat)
        self.mesh.add_cylinder(cx, cz, y0 + 0.015, y0 + 0.02, r_in + 0.004, SMOKED_TINT, key, T, material=GLASS)
        art = self._world_joint(frame, "revolute", [0, 0, -1], [cx - r, 0.5 * (y0 + y1), cz], float(np.radians(self.rng.uniform(150, 180))))
        hkey = key + ".handle"
        self.mesh.add_box([cx + r - 0.05, y0 - 0.025, cz - 0.05], [cx + r - 0.01, y0, cz + 0.05], fin.handle, hkey, T,
                          skip=((1, 1),), material=fin.handle_mat)
        spec = PartSpec(key, f"{label_base}.door_{len(self.parts) + 1}", "door", art, carcass_key, hkey, depth)
        self.parts.append(spec)
        return spec

    def lid(self, frame: WallFrame, W: float, D: float, z_top: float, fin: Finish, carcass_key: str, depth: float,
            label_base: str, thickness: float = 0.06) -> PartSpec:
        """A top lid over [0,W]x[0,D] (chest freezer) hinged along its back edge, opening upwards, with a
        bar under its front lip."""
        T = frame.T
        key = self._name(carcass_key + "_f")
        self.mesh.add_box([-0.01, -0.01, z_top], [W + 0.01, D, z_top + thickness], fin.front, key, T, material=fin.front_mat)
        art = self._world_joint(frame, "revolute", [-1, 0, 0], [W / 2, D, z_top + thickness / 2], float(np.radians(self.rng.uniform(70, 85))))
        hkey = key + ".handle"
        hw = min(0.4, 0.5 * W)
        self.mesh.add_box([W / 2 - hw / 2, -0.045, z_top - 0.01], [W / 2 + hw / 2, -0.01, z_top + 0.02], fin.handle, hkey, T,
                          material=fin.handle_mat)
        spec = PartSpec(key, f"{label_base}.lid_{len(self.parts) + 1}", "lid", art, carcass_key, hkey, depth)
        self.parts.append(spec)
        return spec

    # -- bodies --------------------------------------------------------------------------------
    def body(self, frame: WallFrame, name: str, W: float, D: float, z0: float, H: float, fin: Finish,
             shelves: list[tuple[float, float, float]] = (), dividers: list[tuple[float, float, float]] = (),  # type: ignore[assignment]
             legs: float = 0.0, plinth: float = 0.0, liner: RGB | None = None, t: float = BOARD,
             open_top: bool = False) -> None:
        """A hollow body open at the front (or at the top): sides, top, bottom and back boards, shelves
        (x0, x1, z) and vertical dividers (x, z0, z1) inside, standing on ``legs`` (4 square legs) or a
        recessed ``plinth`` below ``z0``; ``liner`` lines the inside (enamel, plastic) in its colour."""
        T, c, mat = frame.T, fin.body, fin.body_mat
        m = self.mesh
        edge, m.edge = m.edge, m.edge * 1.8  # boards are mostly hidden: coarser, like a decimated scan
        zt = z0 + H
        if plinth > 0:
            m.add_box([0.03, 0.05, 0.0], [W - 0.03, D - 0.02, z0], (45, 45, 47), name, T)
        if legs > 0:
            s = 0.035
            for x in (0.02, W - 0.02 - s):
                for y in (0.03, D - 0.03 - s):
                    m.add_box([x, y, 0.0], [x + s, y + s, z0], fin.body if fin.body_mat != WOOD else (60, 60, 62), name, T,
                              material=METAL if fin.body_mat == WOOD else mat)
        m.add_box([0, 0, z0], [t, D, zt], c, name, T, material=mat)
        m.add_box([W - t, 0, z0], [W, D, zt], c, name, T, material=mat)
        m.add_box([t, 0, z0], [W - t, D - t, z0 + t], c, name, T, material=mat)
        if not open_top:
            m.add_box([t, 0, zt - t], [W - t, D - t, zt], c, name, T, material=mat)
        else:  # the front wall of a chest
            m.add_box([t, 0, z0 + t], [W - t, t, zt], c, name, T, material=mat)
        m.add_box([t, D - t, z0], [W - t, D, zt], c, name, T, material=mat)
        for x0, x1, z in shelves:
            m.add_box([x0, 0.005, z - t / 2], [x1, D - t, z + t / 2], c, name, T, material=mat)
        for x, za, zb in dividers:
            m.add_box([x - t / 2, 0.005, za], [x + t / 2, D - t, zb], c, name, T, material=mat)
        if liner is not None:  # thin inner skin, visible through glass and when open
            li, y_in = 0.003, (t if open_top else 0.0)
            m.add_box([t, y_in, z0 + t], [t + li, D - t, zt - t], liner, name, T, material=GLOSSY)
            m.add_box([W - t - li, y_in, z0 + t], [W - t, D - t, zt - t], liner, name, T, material=GLOSSY)
            m.add_box([t, y_in, z0 + t], [W - t, D - t, z0 + t + li], liner, name, T, material=GLOSSY)
            if not open_top:
                m.add_box([t, 0, zt - t - li], [W - t, D - t, zt - t], liner, name, T, material=GLOSSY)
            m.add_box([t, D - t - li, z0 + t], [W - t, D - t, zt - t], liner, name, T, material=GLOSSY)
        m.edge = edge
        self.statics[name] = name.rsplit("_", 1)[0]

    def shelf_items(self, frame: WallFrame, x0: float, x1: float, z: float, D: float, max_h: float) -> None:
        """Books and cups on a shelf at height ``z`` between x0 and x1 (what one sees through glass)."""
        T = frame.T
        x = x0 + float(self.rng.uniform(0.01, 0.06))
        while x < x1 - 0.05:
            if self.rng.random() < 0.7:  # a run of books
                n = int(self.rng.integers(3, 9))
                for _ in range(n):
                    w = float(self.rng.uniform(0.02, 0.05))
                    h = float(min(max_h - 0.01, self.rng.uniform(0.15, 0.28)))
                    if x + w > x1 - 0.01 or h <= 0.05:
                        break
                    col = tuple(int(v) for v in self.rng.integers(30, 220, 3))
                    dd = float(self.rng.uniform(0.14, min(0.24, D - 0.06)))
                    self.mesh.add_box([x, 0.03, z], [x + w, 0.03 + dd, z + h], col, None, T)
                    x += w + 0.002
            else:  # a cup or a jar
                s = float(self.rng.uniform(0.06, 0.1))
                h = float(min(max_h - 0.01, self.rng.uniform(0.08, 0.16)))
                if x + s > x1 - 0.01 or h <= 0.04:
                    break
                col = tuple(int(v) for v in self.rng.integers(120, 250, 3))
                self.mesh.add_cylinder(x + s / 2, -(0.05 + s / 2), z, z + h, s / 2, col, None, T @ Y_UP, material=GLOSSY)
                x += s + 0.02
            x += float(self.rng.uniform(0.02, 0.12))

    def grid(self, frame: WallFrame, label_base: str, W: float, D: float, z0: float, H: float,
             columns: list[tuple[float, list[tuple[float, str]]]], fin: Finish, handle: str, legs: float = 0.0,
             plinth: float = 0.0, items: bool = True) -> str:
        """A body of side-by-side columns, each a bottom-to-top stack of cells (height fraction, layout),
        under one top; returns the body's key.

        Layouts: ``drawer``, ``drawer2`` (two side by side), ``door_left``, ``door_right``, ``door2``,
        ``flap``, ``drop``, ``glass_left`` / ``glass_right`` / ``glass2`` (glass-panel doors, with
        shelves and things behind them), ``open`` (an open niche, no front) and ``shelf`` (an open
        niche with a shelf and things on it)."""
        name = self._name(label_base)
        wf = np.array([w for w, _ in columns], float)
        xb = W * np.concatenate([[0.0], np.cumsum(wf / wf.sum())])
        shelves, dividers, cells_out = [], [], []
        for (_, cells), xa, xc in zip(columns, xb[:-1], xb[1:]):
            hf = np.array([f for f, _ in cells], float)
            zb = z0 + H * np.concatenate([[0.0], np.cumsum(hf / hf.sum())])
            for z in zb[1:-1]:
                shelves.append((float(xa) + BOARD / 2, float(xc) - BOARD / 2, float(z)))
            for (_, lay), za, zc in zip(cells, zb[:-1], zb[1:]):
                cells_out.append((lay, float(xa), float(xc), float(za), float(zc)))
                if lay.startswith("glass") or lay == "shelf" or (lay.startswith("door") and zc - za > 0.6):
                    zs = 0.5 * (za + zc)  # an inner shelf at half height
                    shelves.append((float(xa) + BOARD / 2, float(xc) - BOARD / 2, zs))
        for x in xb[1:-1]:
            dividers.append((float(x), z0, z0 + H))
        self.body(frame, name, W, D, z0, H, fin, shelves, dividers, legs=legs, plinth=plinth)
        depth = D - BOARD
        g = GAP / 2
        for lay, xa, xc, za, zc in cells_out:
            xa_, xc_, za_, zc_ = xa + g, xc - g, za + g, zc - g
            if lay in ("open", "shelf"):
                if items and lay == "shelf":
                    self.shelf_items(frame, xa + BOARD, xc - BOARD, za + BOARD / 2, D, zc - za - BOARD)
                continue
            glass = lay.startswith("glass")
            kinds = {"door2": ("door_left", "door_right"), "drawer2": ("drawer", "drawer"),
                     "glass2": ("door_left", "door_right"), "glass_left": ("door_left",),
                     "glass_right": ("door_right",)}.get(lay, (lay,))
            if glass and items:
                zs = 0.5 * (za + zc)
                for zz, top in ((za + BOARD / 2, zs - BOARD / 2), (zs + BOARD / 2, zc - BOARD / 2)):
                    self.shelf_items(frame, xa + BOARD, xc - BOARD, zz, D, top - zz)
            fw = float(self.rng.uniform(0.05, 0.08)) if glass else 0.0
            widths = [(xa_, xc_)] if len(kinds) == 1 else [(xa_, 0.5 * (xa + xc) - g), (0.5 * (xa + xc) + g, xc_)]
            for k, (a, b) in zip(kinds, widths):
                self.panel_front(frame, k, a, b, za_, zc_, fin, handle, name, depth, label_base,
                                 glass=(fw, fw, fw, fw) if glass else None, muntins=int(glass and self.rng.random() < 0.25))
        return name


#: (x, y, z) -> (x, -z, y): a cylinder built along y from y0 to y1 around (cx, cz) stands upright
#: from z = y0 to y1 around (x, y) = (cx, -cz)
Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
