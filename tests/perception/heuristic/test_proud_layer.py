"""Bars standing proud of their front, read on an orthophoto fused in front of the plane
(image_fronts.proud_handles, handles.proud_layer)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from react3d_core.camera import look_at
from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.front_cells import Handle, off_background
from react3d_core.perception.heuristic.image_fronts import proud_handles
from react3d_core.perception.heuristic.orthophoto import ColourCalibration, build_orthophotos
from react3d_core.perception.heuristic.planes import Plane
from react3d_core.raster import Rasterizer
from react3d_core.synthetic.render import RayCaster
from tests.perception.heuristic.flat_orthos import flat_ortho

_H, _W = 150, 200  # a 0.6 x 0.8 m front at 4 mm
_ROWS, _COLS = slice(70, 76), slice(60, 120)  # a 24 x 2.4 cm bar
_ON = HeuristicConfig(handles={"proud_layer": 0.03})


def _front(bar: float, rows: slice = _ROWS) -> np.ndarray:
    """A plain front of colour 1 (the plane's mean) with a grey bar of colour ``bar`` at ``rows`` x ``_COLS``."""
    img = np.ones((_H, _W, 3), np.float32)
    img[rows, _COLS] = bar
    return img


def _layer_and_plane(on_layer: float, on_plane: float, rows: slice = _ROWS
                     ) -> tuple[list[Handle], list[Handle]]:
    """Bars kept from a layer showing the bar at ``on_layer`` over a plane showing ``on_plane`` there, with
    no handle found on the plane before and with one 3 cm above the bar."""
    layer, plane = flat_ortho(_front(on_layer, rows)), flat_ortho(_front(on_plane, rows))
    cov = np.ones((_H, _W), bool)
    diff = off_background(plane, _ON.handles)
    thr = _ON.handles.contrast
    above = rows.start - 8  # 3.2 cm above the bar's top row
    found = Handle((_COLS.start, above, _COLS.stop, above + 2), True, np.zeros((0, 2), np.int64))
    return (proud_handles(layer, [], cov, cov, diff, thr, _ON),
            proud_handles(flat_ortho(_front(on_layer, rows)), [found], cov, cov, diff, thr, _ON))


def test_colour_distance_of_a_grey_bar_hand_computed() -> None:
    """A grey bar of colour b on a front of colour 1 stands out by |b - 1| x 128 quantised to 8 bits, / 128,
    times sqrt(3) (three equal channels): b = 2 -> 256, clipped to 255: 127 / 128 x 1.732 = 1.7186, b = 1.3 -> 38 / 128 x 1.732 = 0.514, b = 1.8 ->
    102 / 128 x 1.732 = 1.380 (the 12 cm median background is the front, the bar filling under half of it)."""
    for b, want in ((2.0, 1.7186), (1.3, 0.514), (1.8, 1.380)):
        d = off_background(flat_ortho(_front(b)), _ON.handles)
        assert float(d[_ROWS, _COLS].mean()) == pytest.approx(want, abs=2e-3)
        assert float(d[10, 10]) == 0.0


def test_a_bar_sharp_in_front_and_smeared_on_the_plane_is_kept() -> None:
    """Layer 1.7186, plane 0.514: over proud_contrast 1.2 and 2 x 0.514 = 1.03, and the plane shows it by more
    than its threshold 0.12: kept, as one horizontal bar at its own pixels; a handle already found 3 cm above
    it (within proud_near 5 cm) is the same bar, so then none is added."""
    alone, beside = _layer_and_plane(2.0, 1.3)
    assert len(alone) == 1 and alone[0].horizontal
    assert alone[0].box == (_COLS.start, _ROWS.start, _COLS.stop, _ROWS.stop)
    assert beside == []


@pytest.mark.parametrize("on_layer, on_plane, why", [
    (2.0, 1.8, "sharp on the plane (1.380 x 2 > 1.7186): a seam or a painted line"),
    (2.0, 1.0, "not on the plane at all (0 < 0.12): seen past the plane's edge through the layer"),
    (1.6, 1.1, "faint on the layer (76 / 128 x 1.732 = 1.028 < proud_contrast 1.2; the plane 0.162): an edge's shadow"),
])
def test_bars_the_plane_explains_are_not_added(on_layer: float, on_plane: float, why: str) -> None:
    alone, _ = _layer_and_plane(on_layer, on_plane)
    assert alone == [], why


def test_no_proud_bar_near_the_plane_outline() -> None:
    """The same bar 2.8 cm below the front's top (rows 7-12: inside find_handles' 2 cm margin, but within
    proud_margin 5 cm of the coverage's edge, where the layer sees past the plane; the grid's edge counts as
    the coverage's) is not added; with proud_margin 0 it is."""
    rows = slice(7, 13)
    assert _layer_and_plane(2.0, 1.3, rows)[0] == []
    cfg = HeuristicConfig(handles={"proud_layer": 0.03, "proud_margin": 0.0})
    layer, plane = flat_ortho(_front(2.0, rows)), flat_ortho(_front(1.3, rows))
    cov = np.ones((_H, _W), bool)
    assert len(proud_handles(layer, [], cov, cov, off_background(plane, cfg.handles), 0.12, cfg)) == 1


def test_the_layer_is_on_by_default() -> None:
    assert HeuristicConfig().handles.proud_layer == 0.03


def _box(lo: tuple[float, float, float], hi: tuple[float, float, float], rgb: tuple[int, int, int]) -> TriMesh:
    b = trimesh.creation.box(bounds=np.array([lo, hi]))
    return TriMesh(np.asarray(b.vertices, float), np.asarray(b.faces, np.int64),
                   np.tile(np.array(rgb, np.uint8), (len(b.vertices), 1)))


def test_a_layer_in_front_paints_a_proud_bar_where_it_stands() -> None:
    """A dark sheet (y = 0, facing -y) with a white bar 40 x 1.2 cm standing 1.8-3 cm in front of it at
    z = 0.5, which the scan lacks (no depth return: the scan is the sheet alone). Five views from 0.9 to 2.3 m
    high look down at it: on the plane each paints the bar lower by 3 cm x the tangent of its angle (1.0-3.7
    cm), so the fused plane holds it below its place; on a layer 2.4 cm in front (the bar's middle) every view
    paints it where it stands (z 0.494-0.506, and its top face seen from above)."""
    sheet = _box((-0.2, 0.0, 0.0), (1.2, 0.1, 1.0), (25, 25, 25))
    bar = _box((0.3, -0.03, 0.494), (0.7, -0.018, 0.506), (240, 240, 240))
    scene = TriMesh(np.concatenate([sheet.vertices, bar.vertices]),
                    np.concatenate([sheet.faces, bar.faces + sheet.n_vertices]),
                    np.concatenate([sheet.colors, bar.colors]))
    caster, rng = RayCaster(scene), np.random.default_rng(2)
    W, H = 480, 360
    K = np.array([[420.0, 0, 240], [0, 420.0, 180], [0, 0, 1]])
    frames, images = [], {}
    for i, (ex, ez) in enumerate(((0.1, 0.9), (0.4, 1.3), (0.6, 1.7), (0.8, 2.0), (0.5, 2.3))):
        c2w = look_at(np.array([ex, -1.2, ez]), np.array([0.5, 0.0, 0.5]))
        fid = f"frame_{i:06d}"
        images[fid] = caster.rgb(caster.cast(K, c2w, W, H), rng)
        frames.append(Frame(frame_id=fid, rgb=ImageRef(path=Path(f"{fid}.png"), kind="png"),
                            intrinsics=Intrinsics.from_K(K, W, H), pose=c2w))
    plane = Plane(np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.0, np.arange(sheet.n_faces),
                  (0.1, 0.9), (0.3, 0.7), 0.32)
    read = lambda f: images[f.frame_id]  # noqa: E731
    cfg = HeuristicConfig(calibration={"enabled": False})
    (on_plane,), calib, _ = build_orthophotos([plane], frames, Rasterizer(sheet), sheet.n_faces, read, cfg.ortho,
                                              cfg.calibration, cfg.registration, layer=0.024)
    assert calib == ColourCalibration(before=calib.before, after=calib.after)
    in_front = on_plane.layer
    assert in_front is not None and in_front.layer is None and in_front.plane.d == pytest.approx(0.024)
    assert in_front.color.shape == on_plane.color.shape and (in_front.u0, in_front.v_top) == (on_plane.u0, on_plane.v_top)
    alone, _, _ = build_orthophotos([plane], frames, Rasterizer(sheet), sheet.n_faces, read, cfg.ortho, cfg.calibration,
                                    cfg.registration)
    assert alone[0].layer is None and np.array_equal(alone[0].color, on_plane.color)

    def bright_z(o) -> np.ndarray:  # noqa: ANN001
        """Heights of the pixels painted bright over the bar's columns (u 0.35-0.65)."""
        cols = np.arange(o.color.shape[1])
        u, _ = o.to_uv(cols, np.zeros_like(cols))
        keep = (u > 0.35) & (u < 0.65)
        rows, cc = np.nonzero((o.color.mean(-1) > 3.0 * np.median(o.color.mean(-1)[o.valid])) & keep[None])
        return o.to_uv(cc, rows)[1]

    zl, zp = bright_z(in_front), bright_z(on_plane)
    # the bar's face and its lit top (1.2 cm deep, seen from above): 2.8 cm tall around z = 0.5 in front ...
    assert len(zl) > 0 and abs(float(np.median(zl)) - 0.5) < 0.006 and zl.max() - zl.min() < 0.035
    # ... and 1-4 cm lower on the plane (median 0.474 here)
    assert len(zp) > 0 and float(np.median(zp)) < 0.485 and zp.max() <= 0.49
