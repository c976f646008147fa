"""Where the image path loses dark fronts (the depth sensor missed them; the scan is completed with a slab
coloured from the views): the mechanisms traced on the dark tuning scenes, each on a constructed
orthophoto — knob handles, which have no bar's shape."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import FrontRulesConfig, HeuristicConfig
from react3d_core.perception.heuristic.front_cells import Handle, _is_knob, find_handles, knobs_in_patterns, split_cells
from react3d_core.perception.heuristic.fronts import Front, _joint
from tests.perception.heuristic.flat_orthos import flat_ortho


_ortho = flat_ortho


def _disc(img: np.ndarray, r: int, c: int, radius: int, value: float) -> None:
    rr, cc = np.mgrid[:img.shape[0], :img.shape[1]]
    img[(rr - r) ** 2 + (cc - c) ** 2 <= radius ** 2] = value


def test_knob_shape() -> None:
    """At 4 mm: a 12 x 12 px blob (4.8 cm) filling 113 px (a disc of radius 6: 0.78 of its box) is a knob;
    the same box filled 0.5 (speckle on a dark front) is not, nor a 20 x 20 px blob (8 cm: a socket), a
    5 x 5 px one (2 cm) or a 12 x 24 px one (aspect 2 > 1.6)."""
    p = HeuristicConfig(handles={"knobs": True}).handles
    assert _is_knob(12, 12, 113, 0.004, p)
    assert not _is_knob(12, 12, 72, 0.004, p)
    assert not _is_knob(20, 20, 314, 0.004, p)
    assert not _is_knob(5, 5, 20, 0.004, p)
    assert not _is_knob(12, 24, 230, 0.004, p)


def test_knobs_split_stacked_dark_drawers() -> None:
    """A 0.44 x 0.75 m dark column (110 x 188 px, 0.15 of the plane's exposure, a little noise, no visible
    seam) holding three drawers, each with a pale knob 5 cm across (disc radius 6 px) in its middle at rows
    31, 94, 157. A knob is no bar (10-50 cm long, aspect >= 2.2), so without knobs the column has no
    handle and stays one cell; with them it is cut between each pair of knobs, into three cells."""
    rng = np.random.default_rng(7)
    img = np.full((188, 110, 3), 0.15, np.float32) + rng.normal(0, 0.003, (188, 110, 3)).astype(np.float32)
    for r in (31, 94, 157):
        _disc(img, r, 55, 6, 0.9)
    o = _ortho(img)
    cov = np.ones(img.shape[:2], bool)
    off = HeuristicConfig(handles={"knobs": False})
    on = HeuristicConfig(handles={"knobs": True})
    assert find_handles(o, cov, off) == []
    knobs = find_handles(o, cov, on)
    assert len(knobs) == 3 and all(k.knob for k in knobs)
    assert len(split_cells(o, cov, find_handles(o, cov, off), off)) == 1
    cells = split_cells(o, cov, knobs, on)
    assert len(cells) == 3
    assert [len(c.handles) for c in cells] == [1, 1, 1]
    cuts = sorted(c.r0 for c in cells)[1:]
    assert 40 <= cuts[0] <= 85 and 103 <= cuts[1] <= 148


def _front(w: float, h: float) -> Front:
    return Front(facet=-1, handle_facets=[], center=np.array([w / 2, 0.0, 0.5 + h / 2]), n_out=np.array([0.0, -1.0, 0.0]),
                 u=np.array([1.0, 0.0, 0.0]), extent_u=(0.0, w), extent_v=(0.5, 0.5 + h), faces=np.zeros(0, np.int64))


def _knob_points(u: float, v: float, d: float = 0.04) -> np.ndarray:
    """Points of a knob d across, centred at (u, z=v) on the plane y = 0: a square grid (extent d both ways)."""
    g = np.linspace(-d / 2, d / 2, 5)
    uu, vv = np.meshgrid(g + u, g + v)
    return np.stack([uu.ravel(), np.zeros(uu.size), vv.ravel()], 1)


def test_knob_types_the_joint_by_where_it_sits() -> None:
    """A knob has no direction (its extent is the same both ways), so ``ptp(u) >= ptp(v)`` read it as a
    horizontal bar and a 0.45 x 0.7 m door with a knob at its right edge became a drop door. Read by its
    place: at the edge (0.19 m from the centre line, over 0.25 x 0.45) it is a door hinged on the far (left)
    side; centred on a 0.5 x 0.2 m front it is a drawer. With ``knob_centre`` 0.5 every knob reads as
    a horizontal bar, as before the rule."""
    r = FrontRulesConfig()
    door = _front(0.45, 0.7)
    kind, art = _joint(door, _knob_points(0.415, 0.85), [], r)
    assert kind == "door" and abs(art.axis[2]) == 1.0 and art.origin[0] == 0.0
    assert _joint(door, _knob_points(0.415, 0.85), [], FrontRulesConfig(knob_centre=0.5))[0] == "drop"
    drawer = _front(0.5, 0.2)
    assert _joint(drawer, _knob_points(0.25, 0.6), [], r)[0] == "drawer"


def test_a_blob_larger_than_a_knob_keeps_the_bar_reading() -> None:
    """A wall cabinet door 0.5 x 0.79 m (bottom at 1.275 m, above ``flap_min_top``) with a compact blob
    6 x 9.5 cm in its middle (a raised panel's boss read as a handle): its aspect (1.58) is a knob's,
    and read by its place (centred) it made the door a top-hinged flap. It is larger than any knob
    (``knob_max_size`` 7 cm), so it keeps the bar reading: taller than wide, a vertical hinge. A 4 cm knob
    at the same place still reads as a flap's knob."""
    r = FrontRulesConfig()
    door = Front(facet=-1, handle_facets=[], center=np.array([0.25, 0.0, 1.67]), n_out=np.array([0.0, -1.0, 0.0]),
                 u=np.array([1.0, 0.0, 0.0]), extent_u=(0.0, 0.5), extent_v=(1.275, 2.065), faces=np.zeros(0, np.int64))
    boss = _knob_points(0.25, 1.66, 0.06)  # a centimetre under the middle: a flap's place
    boss[:, 2] = 1.66 + (boss[:, 2] - 1.66) * 0.095 / 0.06
    kind, art = _joint(door, boss, [], r)
    assert kind == "door" and abs(art.axis[2]) == 1.0
    assert _joint(door, boss, [], FrontRulesConfig(knob_max_size=0.1))[0] == "flap"
    assert _joint(door, _knob_points(0.25, 1.66), [], r)[0] == "flap"


def test_plinth_strip_comes_off_a_handled_front() -> None:
    """A dark drawer front 0.5 m wide (125 px, 0.15 of the exposure) with a pale bar handle (0.18 m x 2 cm,
    rows 45-49), standing on a 0.1 m plinth strip of another shade (rows 100-124, 0.4), as a slab over a
    dark unit takes it in. The colour step at row 100 is the cell's strongest line, but a horizontal cut
    in a cell holding a handle must leave a handle on both sides: without the strip rule
    (``cells.edge_strip`` 0) the cut is refused and the front keeps the plinth (125 rows); with it the
    handle-less strip along the bottom edge (25 rows = 0.1 m <= 0.2 m) is cut off and dropped."""
    rng = np.random.default_rng(11)
    img = np.full((125, 125, 3), 0.15, np.float32) + rng.normal(0, 0.003, (125, 125, 3)).astype(np.float32)
    img[100:] = 0.4 + rng.normal(0, 0.003, (25, 125, 3)).astype(np.float32)
    img[45:50, 40:85] = 0.9
    o = _ortho(img)
    cov = np.ones(img.shape[:2], bool)
    off = HeuristicConfig(cells={"edge_strip": 0.0})
    on = HeuristicConfig(handles={"knobs": True})
    handles = find_handles(o, cov, on)
    assert len(handles) == 1 and not handles[0].knob
    kept = split_cells(o, cov, handles, off)
    assert [(c.r0, c.r1) for c in kept] == [(0, 125)]
    trimmed = split_cells(o, cov, handles, on)
    assert len(trimmed) == 1 and trimmed[0].r0 == 0 and 98 <= trimmed[0].r1 <= 101
    assert len(trimmed[0].handles) == 1
    # a handle-less part taller than edge_strip is not a strip: the cut is refused as before
    assert [(c.r0, c.r1) for c in split_cells(o, cov, handles, HeuristicConfig(cells={"edge_strip": 0.08}))] == [(0, 125)]


def test_bench_dark_fronts_box_and_f1_by_hand() -> None:
    """benchmarks/bench_dark_fronts.py scores a front as a 2 cm box on its rectangle: a 0.4 x 0.2 m front
    (u along x) against a part box 0.4 x 0.3 m sharing its left, right and bottom edges has IoU
    0.08 / 0.12 = 2/3 (front_box_iou, the evaluator's); a tall front's box has z as its longest side. F1 is
    2 TP / (predictions + parts): 3 matches of 4 predictions for 5 parts -> 6 / 9."""
    from benchmarks.bench_dark_fronts import f1, front_box
    from react3d_core.data.parts import OBB
    from react3d_core.metrics.scene_metrics import front_box_iou

    wide = Front(facet=-1, handle_facets=[], center=np.array([0.2, 0.0, 0.6]), n_out=np.array([0.0, -1.0, 0.0]),
                 u=np.array([1.0, 0.0, 0.0]), extent_u=(0.0, 0.4), extent_v=(0.5, 0.7), faces=np.zeros(0, np.int64))
    part = OBB(center=(0.2, 0.0, 0.65), axes=((1.0, 0, 0), (0, 0, 1.0), (0, -1.0, 0)), extents=(0.4, 0.3, 0.02))
    box = front_box(wide)
    assert box.extents == (0.4, pytest.approx(0.2), 0.02) and box.axes[0] == (1.0, 0.0, 0.0)
    assert front_box_iou(box, part) == pytest.approx(2 / 3, abs=1e-6)
    tall = _front(0.4, 0.7)
    assert front_box(tall).axes[0] == (0.0, 0.0, 1.0) and front_box(tall).extents[0] == pytest.approx(0.7)
    assert f1(3, 4, 5) == pytest.approx(6 / 9)
    assert f1(0, 0, 0) == 0.0



def test_knobs_are_kept_in_patterns_and_a_lone_blob_is_not() -> None:
    """The three drawer knobs of the column above line up (centres in column 55, 5 cm discs): with
    ``knob_pair`` 2 cm each has a like knob in its column, so all three stay. A lone 5 cm pale disc on a
    0.44 x 0.3 m front (a blob on a real front passing the knob tests) has no other knob on its plane and
    goes; so does a second disc 8 cm off its row and column (40 px right, 20 px down), and a disc that lines
    up with it but is much smaller (a 2.8 cm square beside the 5.2 cm disc: 13 / 7 px > 1.4)."""
    rng = np.random.default_rng(7)
    on = HeuristicConfig(handles={"knobs": True, "knob_pair": 0.02})
    img = np.full((188, 110, 3), 0.15, np.float32) + rng.normal(0, 0.003, (188, 110, 3)).astype(np.float32)
    for r in (31, 94, 157):
        _disc(img, r, 55, 6, 0.9)
    o, cov = _ortho(img), np.ones(img.shape[:2], bool)
    assert len(find_handles(o, cov, on)) == 3
    assert len(find_handles(o, cov, on.model_copy(update={"handles": on.handles.model_copy(update={"knob_pair": 0.0})}))) == 3

    lone = np.full((75, 110, 3), 0.15, np.float32) + rng.normal(0, 0.003, (75, 110, 3)).astype(np.float32)
    _disc(lone, 30, 40, 6, 0.9)
    o, cov = _ortho(lone), np.ones(lone.shape[:2], bool)
    assert len(find_handles(o, cov, HeuristicConfig(handles={"knobs": True, "knob_pair": 0.0}))) == 1
    assert find_handles(o, cov, on) == []
    _disc(lone, 50, 80, 6, 0.9)  # off its row (20 px) and column (40 px)
    o = _ortho(lone)
    assert len(find_handles(o, cov, HeuristicConfig(handles={"knobs": True, "knob_pair": 0.0}))) == 2
    assert find_handles(o, cov, on) == []
    small = np.full((75, 110, 3), 0.15, np.float32) + rng.normal(0, 0.003, (75, 110, 3)).astype(np.float32)
    _disc(small, 30, 40, 6, 0.9)
    small[27:34, 77:84] = 0.9  # a square knob in its row, 2.8 cm across
    o = _ortho(small)
    found = find_handles(o, cov, HeuristicConfig(handles={"knobs": True, "knob_pair": 0.0}))
    assert len(found) == 2 and all(k.knob for k in found)
    assert find_handles(o, cov, on) == []


def test_two_knobs_side_by_side_are_cut_apart_only_at_a_seam() -> None:
    """A 0.6 x 0.2 m drawer (150 x 50 px) with two 5 cm knobs at a quarter and three quarters of its width
    (columns 37 and 112) and no seam: split between its handles it was halved at the middle (column 75).
    With ``seams.knob_seam`` it stays one cell. Two 0.3 m drawers side by side, the same knobs, with a 2 px
    dark seam at column 75 (0.05 under the fronts' 0.6), are cut there either way."""
    rng = np.random.default_rng(3)

    def cells(seam: bool, knob_seam: bool) -> list:
        img = np.full((50, 150, 3), 0.6, np.float32) + rng.normal(0, 0.003, (50, 150, 3)).astype(np.float32)
        if seam:
            img[:, 74:76] = 0.55
        for c in (37, 112):
            _disc(img, 25, c, 6, 0.1)
        o, cov = _ortho(img), np.ones(img.shape[:2], bool)
        cfg = HeuristicConfig(handles={"knobs": True}, seams={"knob_seam": knob_seam})
        hs = find_handles(o, cov, cfg)
        assert len(hs) == 2 and all(h.knob for h in hs)
        return split_cells(o, cov, hs, cfg)

    assert len(cells(False, False)) == 2
    assert len(cells(False, True)) == 1
    for knob_seam in (False, True):
        got = cells(True, knob_seam)
        assert len(got) == 2 and 72 <= min(c.c1 for c in got) <= 77


def test_a_door_pairs_knobs_by_its_middle_are_cut_apart_with_no_seam() -> None:
    """A black 0.8 x 0.8 m door pair (200 x 200 px at 4 mm) with no seam line, two 5 cm knobs (radius 6)
    at one height either side of its middle, columns 88 and 112, found as knob boxes [83, 94) and
    [107, 118) (the blob's rim is opened off): a 13 px gap (>= one knob's 11 px width, <= 0.3 x 200 = 60 px),
    midpoint (94 + 107) // 2 = 100, the cell's middle. With ``seams.knob_pair_gap`` it is cut there into two doors, one knob each; off, it stays
    one front. A wide drawer's knobs at its quarters (the test above) stay one cell either way."""
    rng = np.random.default_rng(5)
    img = np.full((200, 200, 3), 0.08, np.float32) + rng.normal(0, 0.003, (200, 200, 3)).astype(np.float32)
    for c in (88, 112):
        _disc(img, 60, c, 6, 0.7)
    o, cov = _ortho(img), np.ones(img.shape[:2], bool)
    got = {}
    for gap in (0.0, 0.3):
        cfg = HeuristicConfig(handles={"knobs": True}, seams={"knob_pair_gap": gap})
        hs = find_handles(o, cov, cfg)
        assert len(hs) == 2 and all(h.knob for h in hs)
        got[gap] = split_cells(o, cov, hs, cfg)
    assert len(got[0.0]) == 1
    assert len(got[0.3]) == 2 and min(c.c1 for c in got[0.3]) == 100
    assert all(len(c.handles) == 1 for c in got[0.3])


def test_door_pair_knobs_hand_computed() -> None:
    """Knob boxes (c0, r0, c1, r1) in a cell of columns [0, 200), gap share 0.3 (60 px), centre share 0.1
    (20 px): boxes [82, 95) and [106, 119): gap 11 >= 13? no (a knob's width is 13) -> False; [80, 93) and
    [107, 120): gap 14 >= 13, midpoint 100 -> True; [40, 53) and [66, 79): gap 13, midpoint 59.5, 40.5 px
    off the middle -> False; rows [60, 73) and [80, 93): not at one height -> False; gap 0 -> off."""
    from react3d_core.config.heuristic import SeamConfig
    from react3d_core.perception.heuristic.front_cells import _door_pair_knobs

    p = SeamConfig(knob_pair_gap=0.3, knob_pair_centre=0.1)
    assert not _door_pair_knobs((82, 60, 95, 73), (106, 60, 119, 73), 0, 200, p)
    assert _door_pair_knobs((80, 60, 93, 73), (107, 60, 120, 73), 0, 200, p)
    assert not _door_pair_knobs((40, 60, 53, 73), (66, 60, 79, 73), 0, 200, p)
    assert not _door_pair_knobs((80, 60, 93, 73), (107, 80, 120, 93), 0, 200, p)
    assert not _door_pair_knobs((80, 60, 93, 73), (107, 60, 120, 73), 0, 200, SeamConfig(knob_pair_gap=0.0))


def _knob(c: int, r: int, side: int = 11) -> Handle:
    """A knob handle ``side`` px square centred near (c, r)."""
    box = (c - side // 2, r - side // 2, c - side // 2 + side, r - side // 2 + side)
    return Handle(box, True, np.array([[c, r]]), True)


def test_a_row_of_close_knobs_is_a_control_panel_and_far_rows_are_no_pair() -> None:
    """At 4 mm (tolerance 2 cm = 5 px, reach 1 m = 250 px, panel gap 16 cm = 40 px), 11 px knobs:
    - four in a row 32 px (13 cm) apart (an oven's control panel, the trace of tuning scene 310) all go;
      three of them 50 px (20 cm) apart are fronts' knobs in a row, and stay;
    - two in a row 300 px (1.2 m) apart (blobs along the floor line) go; 200 px (0.8 m) apart they stay;
    - a door pair's two knobs 24 px (10 cm) apart stay (two are no panel)."""
    def kept(hs: list[Handle]) -> int:
        return len(knobs_in_patterns(hs, 5, 1.4, 250, 40))

    assert kept([_knob(100 + 32 * i, 50) for i in range(4)]) == 0
    assert kept([_knob(100 + 50 * i, 50) for i in range(3)]) == 3
    assert kept([_knob(100 + 32 * i, 50) for i in range(4)] + [_knob(600, 300)]) == 0
    assert kept([_knob(100, 300), _knob(400, 300)]) == 0
    assert kept([_knob(100, 300), _knob(300, 300)]) == 2
    assert kept([_knob(100, 50), _knob(124, 50)]) == 2
    assert len(knobs_in_patterns([_knob(100 + 32 * i, 50) for i in range(4)], 5, 1.4, 250, 0.0)) == 4


def test_a_knob_only_cell_is_cut_at_a_seam_with_a_knob_on_one_side() -> None:
    """A 0.44 x 0.66 m column (110 x 165 px) of three drawers 55 px tall, 2 px dark seams at rows 54 and
    109; the lower two carry a 5 cm knob each (rows 82 and 137, a pair in one column), the top one none (its
    single knob stood alone and was not taken). A horizontal cut must leave a handle on both sides, so the
    seam under the top drawer was refused and the top drawer merged with the middle one (2 cells). With
    ``cells.knobs_any_side`` a cell holding only knobs is cut there: 3 cells, cut at the seams."""
    rng = np.random.default_rng(5)
    img = np.full((165, 110, 3), 0.6, np.float32) + rng.normal(0, 0.003, (165, 110, 3)).astype(np.float32)
    img[54:56] = 0.45
    img[109:111] = 0.45
    for r in (82, 137):
        _disc(img, r, 55, 6, 0.1)
    o, cov = _ortho(img), np.ones(img.shape[:2], bool)
    got = {}
    for on in (False, True):
        cfg = HeuristicConfig(cells={"knobs_any_side": on})
        hs = find_handles(o, cov, cfg)
        assert len(hs) == 2 and all(h.knob for h in hs)
        got[on] = sorted((c.r0, c.r1) for c in split_cells(o, cov, hs, cfg))
    assert len(got[False]) == 2
    assert len(got[True]) == 3
    assert 52 <= got[True][0][1] <= 57 and 107 <= got[True][1][1] <= 112


def test_no_cut_runs_through_a_lone_knob() -> None:
    """A 0.8 x 0.6 m chest (200 x 150 px at 4 mm): a wide top drawer (rows 0-48) with one 5 cm knob in its
    middle (column 100), over two rows of two drawers each, 2 px seams at rows 49 and 99 and a darker one
    down column 100 below the top drawer, a knob in the middle of each. The four lower knobs line up in
    pairs and are handles; the top one stands alone and is not. The column seam's line runs on up through
    it, so the top drawer was halved (6 cells); with ``cells.lone_knobs_block`` it stays whole (5 cells)."""
    rng = np.random.default_rng(11)
    img = np.full((150, 200, 3), 0.6, np.float32) + rng.normal(0, 0.003, (150, 200, 3)).astype(np.float32)
    img[49:51] = 0.5
    img[99:101] = 0.5
    img[50:, 99:101] = 0.4
    _disc(img, 25, 100, 6, 0.1)
    for r in (75, 125):
        for c in (50, 150):
            _disc(img, r, c, 6, 0.1)
    o, cov = _ortho(img), np.ones(img.shape[:2], bool)
    got = {}
    for on in (False, True):
        cfg = HeuristicConfig(cells={"lone_knobs_block": on})
        lone: list[Handle] = []
        hs = find_handles(o, cov, cfg, lone=lone)
        assert len(hs) == 4 and len(lone) == 1 and lone[0].knob
        got[on] = sorted((c.r0, c.c0, c.r1, c.c1) for c in split_cells(o, cov, hs, cfg, None, lone))
    assert len(got[False]) == 6 and [c for c in got[False] if c[0] == 0][0][3] <= 101
    assert len(got[True]) == 5 and got[True][0][:2] == (0, 0) and got[True][0][3] == 200
