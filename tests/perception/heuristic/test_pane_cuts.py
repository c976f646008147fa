"""Glass panes bar the cell splitter: no cut runs through a pane or along its edge, while the seam between
two glass doors is still cut; a plane's side edges as the views see them frame panes (hand-made grids)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig
from react3d_core.perception.heuristic.front_cells import Cell, _pane_blocks, pane_boxes, split_cells
from react3d_core.perception.heuristic.image_fronts import seen_rim
from react3d_core.perception.heuristic.portholes import porthole_core

from tests.perception.heuristic.flat_orthos import flat_ortho

RES = 0.004


def test_pane_boxes_are_grown_bounding_boxes_clipped_to_the_grid():
    panes = np.zeros((100, 120), bool)
    panes[10:40, 20:50] = True
    panes[60:98, 100:120] = True  # touches the right edge: the box is clipped there
    assert pane_boxes(panes, 3) == [(17, 7, 53, 43), (97, 57, 120, 100)]
    assert pane_boxes(np.zeros((5, 5), bool), 3) == []
    panes[20:22, 50:70] = True  # a leak 2 px tall out of the first pane's side: not its core
    assert pane_boxes(panes, 3)[0] == (17, 7, 53, 43)
    assert pane_boxes(panes, 3, core=0.0)[0] == (17, 7, 73, 43)  # the bounding box


def test_pane_blocks_are_the_boxes_lines_inside_a_cell_they_overlap():
    boxes = [(17, 7, 53, 43), (97, 57, 120, 100)]
    pc, pr = _pane_blocks(Cell(0, 0, 60, 50), boxes)  # overlaps the first box only
    assert np.flatnonzero(pc).tolist() == list(range(17, 53))
    assert np.flatnonzero(pr).tolist() == list(range(7, 43))
    pc, pr = _pane_blocks(Cell(30, 20, 110, 70), boxes)  # both: local indices, clipped to the cell
    assert np.flatnonzero(pc).tolist() == list(range(0, 23)) + list(range(67, 80))
    assert np.flatnonzero(pr).tolist() == list(range(0, 23)) + list(range(37, 50))
    pc, pr = _pane_blocks(Cell(60, 0, 90, 50), boxes)  # none
    assert not pc.any() and not pr.any()


def glass_doors(n_doors: int) -> tuple[np.ndarray, np.ndarray]:
    """``n_doors`` glass doors side by side, each 0.4 x 0.8 m (100 x 200 px) with a 5 cm frame: the pane is
    painted a shade lighter than the frame with a dark 2 px line along its edge (the frame's shaded inner
    edge); doors meet at a dark 1 px seam. Returns the image and the panes' mask."""
    rng = np.random.default_rng(3)
    img = np.full((200, 100 * n_doors, 3), 0.7, np.float32) + rng.normal(0, 0.003, (200, 100 * n_doors, 3)).astype(np.float32)
    panes = np.zeros((200, 100 * n_doors), bool)
    for k in range(n_doors):
        c0 = 100 * k
        img[12:188, c0 + 12:c0 + 88] = 0.4
        img[14:186, c0 + 14:c0 + 86] = 0.8
        panes[12:188, c0 + 12:c0 + 88] = True
        if k:
            img[:, c0] = 0.3
    return img, panes


def test_a_glass_door_is_not_cut_along_its_pane_and_two_are_cut_at_their_seam():
    cfg = HeuristicConfig()
    img, panes = glass_doors(1)
    img[:, 13] = 0.3  # the stile's shaded inner edge, run on over the rails: a straight dark line top to bottom
    img[100:103, :] = 0.3  # a shelf's edge seen through the pane, lined up with a dark joint in both stiles
    o, cov = flat_ortho(img), np.ones(panes.shape, bool)
    free = split_cells(o, cov, [], cfg)
    assert len(free) > 1  # without the panes both read as seams
    cells = split_cells(o, cov, [], cfg, panes=panes)
    assert [(c.c0, c.c1) for c in cells] == [(0, 100)]
    assert len(split_cells(o, cov, [], cfg.model_copy(update={"cells": cfg.cells.model_copy(update={"pane_margin": 0.0})}),
                           panes=panes)) > 1  # margin 0: panes do not bar cuts
    img, panes = glass_doors(2)
    o, cov = flat_ortho(img), np.ones(panes.shape, bool)
    cells = split_cells(o, cov, [], cfg, panes=panes)
    assert sorted((c.c0, c.c1) for c in cells) == [(0, 100), (101, 200)]


def test_seen_rim_takes_the_side_edges_with_sides():
    seen = np.zeros((50, 40), bool)
    seen[:, 5:35] = True  # the plane as the views see it: columns 5-34
    seen[10:40, 15:25] = False  # the pane: unseen
    top_bottom = seen_rim(seen, RES, 0.012)  # 3 px
    assert top_bottom.sum() == 2 * 3 * 30  # rows 0-2 and 47-49 of the 30 seen columns
    both = seen_rim(seen, RES, 0.012, sides=True)
    assert both[:, 5:8].all() and both[:, 32:35].all()  # the outer stiles, 3 px wide
    assert both.sum() == 2 * 3 * 30 + 2 * 3 * 44  # ... on the 44 rows between the top and bottom rims
    assert not both[10:40, 8:32].any()


def test_porthole_core_is_the_discs_lines_holding_half_its_widest_line():
    # r = (120 + 120) / 4 = 60; lines within 0.866 r of the centre: ceil(0.134 * 60) = 9 px in from each side
    assert porthole_core((0, 120, 0, 120)) == (9, 9, 111, 111)
    # rows 10-110, cols 20-130: r = (100 + 110) / 4 = 52.5, ceil(0.134 * 52.5) = ceil(7.03) = 8
    assert porthole_core((10, 110, 20, 130)) == (28, 18, 122, 102)


def washing_machine_plate() -> tuple[np.ndarray, np.ndarray, tuple[int, int, int, int]]:
    """A 0.6 x 0.85 m white plate (150 x 212 px): a porthole whose ring and glass are a hole in the coverage
    (radius 55 px, centre row 120, col 75; the ring's box rows 65-176, cols 20-131), the control panel's
    lower edge a dark line across the plate at row 55, and a detergent drawer top left (cols 0-51, rows 0-44)
    outlined by 1 px dark gaps. Returns the image, the coverage and the ring's box."""
    rng = np.random.default_rng(5)
    img = np.full((212, 150, 3), 0.85, np.float32) + rng.normal(0, 0.003, (212, 150, 3)).astype(np.float32)
    img[55, :] = 0.4
    img[45, 0:53] = 0.4
    img[0:46, 52] = 0.4
    yy, xx = np.mgrid[0:212, 0:150]
    cov = np.hypot(yy - 120, xx - 75) > 55
    return img, cov, (65, 176, 20, 131)


def test_no_cut_runs_through_a_porthole_and_the_drawer_above_it_is_cut_out():
    cfg = HeuristicConfig()
    img, cov, ring = washing_machine_plate()
    o = flat_ortho(img)
    core = porthole_core(ring)  # (c0, r0, c1, r1) = (28, 73, 123, 168)

    def through_core(cells: list[Cell]) -> list[tuple[int, int, int, int]]:
        return [(c.r0, c.r1, c.c0, c.c1) for c in cells
                if c.r0 < core[3] and c.r1 > core[1] and (core[0] < c.c0 < core[2] or core[0] < c.c1 < core[2])]

    assert through_core(split_cells(o, cov, [], cfg))  # the glass's hole reads as an outline's corner
    cells = split_cells(o, cov, [], cfg, barred=[core])
    assert not through_core(cells)
    # the drawer's cell ends at its right gap; its bottom gap is under cells.min_side from the door's top
    assert [(c.r0, c.c0, c.c1) for c in cells if c.r0 == 0 and c.c0 == 0] == [(0, 0, 52)]
