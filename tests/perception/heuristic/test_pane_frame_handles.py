"""A glass pane is one door's, and the door has one handle: colour-only handles on a pane's frame go when a
bar standing out of the scan is on the same frame (image_fronts.pane_frame_handles, handles.pane_bar_reach)."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import HandleConfig
from react3d_core.perception.heuristic.front_cells import Handle
from react3d_core.perception.heuristic.image_fronts import pane_frame_handles

_SHAPE = (200, 140)  # an oven door's plane at 4 mm: 0.8 x 0.56 m
_REACH = 25  # 10 cm at 4 mm


def _handle(c0: int, r0: int, c1: int, r1: int) -> Handle:
    cols, rows = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
    return Handle((c0, r0, c1, r1), c1 - c0 >= r1 - r0, np.stack([cols.ravel(), rows.ravel()], 1))


def _oven() -> tuple[np.ndarray, np.ndarray, Handle, Handle]:
    """A pane at rows 50-169, cols 33-119; the door's bar (in the scan) on the top rail at rows 30-38,
    cols 21-111; a shaded patch on the left stile read as a colour handle at rows 138-171, cols 11-19."""
    panes = np.zeros(_SHAPE, bool)
    panes[50:170, 33:120] = True
    bars = np.zeros(_SHAPE, bool)
    bars[30:39, 21:112] = True
    return panes, bars, _handle(21, 30, 112, 39), _handle(11, 138, 20, 172)


def test_the_colour_handle_on_a_bar_framed_pane_goes() -> None:
    panes, bars, bar, patch = _oven()
    # the pane's box grown by 25 px: cols 8..145, rows 25..195; the patch's box (11..20, 138..172) and the
    # bar's (21..112, 30..39) lie inside it
    assert pane_frame_handles([bar, patch], panes, bars, _REACH, 0.5) == [bar]


def test_without_a_bar_in_the_scan_both_stay() -> None:
    panes, _, bar, patch = _oven()
    assert pane_frame_handles([bar, patch], panes, np.zeros(_SHAPE, bool), _REACH, 0.5) == [bar, patch]


def test_a_bar_half_in_the_scan_counts_at_bar_share() -> None:
    panes, bars, bar, patch = _oven()
    bars[:, 66:] = False  # 45 of the bar's 91 columns stand out: 0.495
    assert pane_frame_handles([bar, patch], panes, bars, _REACH, 0.5) == [bar, patch]
    assert pane_frame_handles([bar, patch], panes, bars, _REACH, 0.49) == [bar]


def test_a_handle_beyond_the_frame_stays() -> None:
    panes, bars, bar, _ = _oven()
    # the next door's handle 11-13 cm left of the pane (cols 0..5, the grown box starts at col 8): not this frame's
    other = _handle(0, 100, 5, 134)
    assert pane_frame_handles([bar, other], panes, bars, _REACH, 0.5) == [bar, other]
    assert pane_frame_handles([bar, other], panes, bars, 33, 0.5) == [bar]  # a 13 cm reach takes it in


def test_no_panes_or_off() -> None:
    panes, bars, bar, patch = _oven()
    assert pane_frame_handles([bar, patch], np.zeros(_SHAPE, bool), bars, _REACH, 0.5) == [bar, patch]
    assert pane_frame_handles([bar, patch], panes, bars, 0, 0.5) == [bar, patch]
    assert HandleConfig().pane_bar_reach == pytest.approx(0.1)  # on by default


def test_the_oven_door_is_one_cell_with_the_rule() -> None:
    """The oven door of ``oven_door_image`` (bar in the scan on the top rail, the pane's dark edge, a shaded stile
    patch read as a handle by colour), its pane at rows 50-169, cols 33-119: without the rule the splitter
    cuts the door between the patch and the bar (two cells); with it the bar is the one handle, one cell."""
    from react3d_core.config.heuristic import HeuristicConfig
    from react3d_core.perception.heuristic.front_cells import find_handles, split_cells
    from tests.perception.heuristic.flat_orthos import flat_ortho, oven_door_image

    img, bars = oven_door_image()
    panes = _oven()[0]
    o, cov, cfg = flat_ortho(img), np.ones(_SHAPE, bool), HeuristicConfig()
    found = find_handles(o, cov, cfg, protrusion=bars)
    assert len(split_cells(o, cov, found, cfg)) == 2
    kept = pane_frame_handles(found, panes, bars, _REACH, cfg.handles.bar_share)
    assert [h.box[:2] for h in kept] == [(21, 30)]
    assert len(split_cells(o, cov, kept, cfg)) == 1
