"""The mesh-front veto (a mesh front whose picture is cluttered is no front) on the mechanisms traced on
scene-synthesizer kitchens, whose inset fronts the veto judges once the plane's coverage is read from
rays cast through the scan (image.surface_rays): a small front's corners against the frame around it, wood
grain against the fixed contrast, a bar longer than any handle standing out of the front."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.perception.heuristic.front_cells import off_background, off_threshold
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.image_fronts import VetoEvidence, _cluttered, _hardware
from react3d_core.perception.heuristic.orthophoto import Orthophoto
from tests.perception.heuristic.flat_orthos import flat_ortho

RES = 0.004


def _ortho(img: np.ndarray) -> Orthophoto:
    return flat_ortho(img, RES)


def _front(o: Orthophoto, r0: int, r1: int, c0: int, c1: int) -> Front:
    """A mesh front on the plane of ``o`` covering rows r0..r1-1 and columns c0..c1-1 (pixel edges moved
    a tenth of a pixel inwards, so the rectangle maps back onto exactly those pixels)."""
    e = 0.1 * RES
    u = (c0 * RES + e, c1 * RES - e)
    v = (o.v_top - r1 * RES + e, o.v_top - r0 * RES - e)
    return Front(facet=0, handle_facets=[], center=np.array([0.5 * sum(u), 0.0, 0.5 * sum(v)]),
                 n_out=np.array([0.0, -1.0, 0.0]), u=np.array([1.0, 0.0, 0.0]), extent_u=u, extent_v=v,
                 faces=np.zeros(0, np.int64))


def test_small_front_judged_against_its_own_background_not_the_frame() -> None:
    """A plain 0.2 x 0.12 m drawer (50 x 30 px, colour 0.8) in a frame of colour 1.3. Against the
    orthophoto's 31 x 31 px median (handles.background_win 0.12 m) a drawer pixel i rows and j columns in
    from a corner has (16 + i)(16 + j) drawer pixels in its window and takes the frame's colour when that
    is under half (481): i = 0..14 give j <= 14, 12, 10, 9, 8, 6, 5, 4, 4, 3, 2, 1, 1, 0, 0 — 94 pixels a
    corner, 376 of 1500 = 25 % off, over clutter.max_share 0.18: the drawer was vetoed. Judged against its
    own rectangle's median no pixel is off."""
    img = np.full((200, 200, 3), 1.3, np.float32)
    img[80:110, 70:120] = 0.8
    o = _ortho(img)
    cfg = HeuristicConfig()
    plane_wide = off_background(o, cfg.handles)[80:110, 70:120] > cfg.handles.contrast
    assert plane_wide.sum() == 376
    ev = VetoEvidence(cfg.handles.contrast, _hardware(np.zeros((200, 200), bool), []))
    assert not _cluttered(_front(o, 80, 110, 70, 120), [o], [ev], cfg)


def test_clutter_on_a_front_is_still_clutter() -> None:
    """The same drawer with a poster on it (0.1 x 0.06 m, 25 x 15 = 375 px of 1500, 25 %, colour 1.3): the
    poster is off the drawer's own median, so the front is vetoed; a tiled wall's joints (1 px dark lines
    every 6 px both ways, 500 of 1500 px) are too."""
    cfg = HeuristicConfig()
    ev = VetoEvidence(cfg.handles.contrast, np.zeros((200, 200), bool))
    img = np.full((200, 200, 3), 1.3, np.float32)
    img[80:110, 70:120] = 0.8
    img[85:100, 80:105] = 1.3
    o = _ortho(img)
    assert _cluttered(_front(o, 80, 110, 70, 120), [o], [ev], cfg)
    tiles = np.full((200, 200, 3), 1.0, np.float32)
    tiles[80:110:6, 70:120] = 0.6
    tiles[80:110, 70:120:6] = 0.6
    o = _ortho(tiles)
    joints = (tiles[80:110, 70:120, 0] < 1.0).sum()
    assert joints == 5 * 50 + 9 * 30 - 5 * 9  # 475 of 1500: 32 %
    assert _cluttered(_front(o, 80, 110, 70, 120), [o], [ev], cfg)


def test_wood_grain_is_judged_by_the_planes_threshold() -> None:
    """A 0.4 x 0.2 m front on a grained plane: every column a brightness 1 + 0.1 N(0, 1) (seeded). Against
    the fixed handles.contrast 0.12 about half its pixels are off (a column is off when |N| sqrt(3) 0.1 >
    0.12, P(|N| > 0.69) = 0.49); the plane's threshold (off_threshold: 3 x its median deviation, about 0.35)
    leaves about 4 % (P(|N| > 2.0)). The veto took the fixed contrast and dropped the front."""
    rng = np.random.default_rng(11)
    img = np.repeat((1.0 + 0.1 * rng.standard_normal((1, 300, 1))).astype(np.float32), 150, 0).repeat(3, 2)
    o = _ortho(img)
    cfg = HeuristicConfig()
    thr = off_threshold(off_background(o, cfg.handles), o.n_views > 0, cfg)
    assert 0.3 < thr < 0.4
    hw = np.zeros((150, 300), bool)
    f = _front(o, 50, 100, 100, 200)
    assert _cluttered(f, [o], [VetoEvidence(cfg.handles.contrast, hw)], cfg)
    assert not _cluttered(f, [o], [VetoEvidence(thr, hw)], cfg)


def test_a_bar_standing_out_of_the_front_is_no_clutter() -> None:
    """A 0.8 x 0.16 m drawer (200 x 40 px) with a 0.7 m x 2.8 cm rail (175 x 7 = 1225 px, 15.3 %), longer
    than any handle find_handles takes (handles.length 0.5 m), and its top two rows dark (400 px, 5 %):
    20.3 % is over clutter.max_share. The rail stands out of the plane in the scan (``bars``): left out,
    5 %."""
    img = np.ones((40, 200, 3), np.float32)
    img[16:23, 12:187] = 1.6
    img[0:2] = 0.5
    o = _ortho(img)
    cfg = HeuristicConfig()
    bars = np.zeros((40, 200), bool)
    bars[16:23, 12:187] = True
    f = _front(o, 0, 40, 0, 200)
    assert _cluttered(f, [o], [VetoEvidence(cfg.handles.contrast, _hardware(np.zeros_like(bars), []))], cfg)
    assert not _cluttered(f, [o], [VetoEvidence(cfg.handles.contrast, _hardware(bars, []))], cfg)
