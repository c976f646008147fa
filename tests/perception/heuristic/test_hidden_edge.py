"""Colour at the edge of what the views see is no handle (front_cells._at_hidden_edge, handles.hidden_side and
hidden_depth)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.perception.heuristic.front_cells import find_handles
from tests.perception.heuristic.flat_orthos import flat_ortho

_H, _W = 150, 200  # 0.6 x 0.8 m at 4 mm
_BAR = (slice(70, 76), slice(60, 120))  # a dark 24 x 2.4 cm blob: a bar handle's size


def _panel() -> np.ndarray:
    """A pale plain panel with the dark blob of ``_BAR`` across its middle."""
    rng = np.random.default_rng(5)
    img = np.full((_H, _W, 3), 0.8, np.float32) + rng.normal(0, 0.003, (_H, _W, 3)).astype(np.float32)
    img[_BAR] = 0.2
    return img


def test_colour_along_a_hidden_band_is_no_handle() -> None:
    """The panel's surface is all in the scan (coverage everywhere), but no view sees it below the blob
    (rows 76 on: a chair in front of a sideboard's side). With the rule off the blob is a handle; with the
    defaults (hidden_side 0.5) its lower side's 2 cm band is hidden surface and it goes. Seen all round, it
    stays."""
    o = flat_ortho(_panel())
    o.n_views[76:, :] = 0
    cov = np.ones((_H, _W), bool)
    off, on = HeuristicConfig(handles={"hidden_side": 0.0}), HeuristicConfig()
    assert on.handles.hidden_side == 0.5
    assert len(find_handles(o, cov, off)) == 1
    assert find_handles(o, cov, on) == []
    assert len(find_handles(flat_ortho(_panel()), cov, on)) == 1


def test_hidden_share_of_a_side_hand_computed() -> None:
    """Hidden surface under part of the blob only: under cols 60-84 (25 of its 60 px: 0.42 of the band) it
    stays a handle, under cols 60-94 (35 px: 0.58) it goes (hidden_side 0.5)."""
    cov = np.ones((_H, _W), bool)
    for c1, kept in ((85, True), (95, False)):
        o = flat_ortho(_panel())
        o.n_views[76:, 60:c1] = 0
        assert (len(find_handles(o, cov, HeuristicConfig(handles={"hidden_side": 0.5}))) == 1) == kept


def test_a_bar_the_scan_holds_stays_beside_a_hidden_band() -> None:
    """A blob standing out of the scan (on the protrusion map) is a handle the scan holds, whatever hides the
    plane beside it."""
    o = flat_ortho(_panel())
    o.n_views[76:, :] = 0
    cov = np.ones((_H, _W), bool)
    bars = np.zeros((_H, _W), bool)
    bars[_BAR] = True
    assert len(find_handles(o, cov, HeuristicConfig(handles={"hidden_side": 0.5}), protrusion=bars)) == 1


def test_a_narrow_hidden_strip_is_what_a_handle_hides() -> None:
    """At 4 mm the side band is 5 px (2 cm) and hidden_depth 0.06 m is 15 px: the band 10-15 px below the
    blob (rows 86-90) must be hidden too. Unseen rows 76-85 (4 cm: what a handle or a worktop's overhang
    hides from oblique views): the first band is all hidden, the far one not, so the blob stays a handle;
    with hidden_depth 0 (the first band only) it goes. Unseen down to row 87, the far band is 2 / 5 hidden and the
    blob stays; down to row 88, 3 / 5 (0.6) and it goes."""
    cov = np.ones((_H, _W), bool)
    for r1, depth, kept in ((86, 0.06, True), (86, 0.0, False), (88, 0.06, True), (89, 0.06, False), (91, 0.0, False)):
        o = flat_ortho(_panel())
        o.n_views[76:r1, :] = 0
        got = find_handles(o, cov, HeuristicConfig(handles={"hidden_depth": depth}))
        assert (len(got) == 1) == kept, (r1, depth)


def test_colour_seen_by_few_views_is_no_handle() -> None:
    """The panel is seen by 10 views everywhere (its median), the blob by 1 view: 1 < 0.2 x 10 = 2, so it
    goes (the shore of what the views see: one grazing view's colour); seen by 2 views, 2 < 2 is false and it
    stays. With the rule off (0) it stays; standing out of the scan (the protrusion map) it stays too."""
    cov = np.ones((_H, _W), bool)
    on, off = HeuristicConfig(), HeuristicConfig(handles={"few_views": 0.0})
    assert on.handles.few_views == 0.2

    def ortho(views: int):  # noqa: ANN202 - a test helper
        o = flat_ortho(_panel())
        o.n_views[:] = 10
        o.n_views[_BAR] = views
        return o

    assert find_handles(ortho(1), cov, on) == []
    assert len(find_handles(ortho(2), cov, on)) == 1
    assert len(find_handles(ortho(1), cov, off)) == 1
    bars = np.zeros((_H, _W), bool)
    bars[_BAR] = True
    assert len(find_handles(ortho(1), cov, on, protrusion=bars)) == 1
