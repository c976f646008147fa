"""Round doors (a washing machine's porthole) from the ring standing proud of its front plate."""

from __future__ import annotations

import cv2
import numpy as np

from react3d_core.config.heuristic import FrontRulesConfig, PortholeConfig
from react3d_core.metrics.geometry import joint_class
from react3d_core.perception.heuristic.fronts import Front, _joint
from react3d_core.perception.heuristic.image_fronts import _overlap, _plate_strip
from react3d_core.perception.heuristic.portholes import find_portholes

RES = 0.004  # m per grid px, as the orthophotos
N = np.array([0.0, -1.0, 0.0])  # facing -y; u = z x n = (1, 0, 0)
U = np.array([1.0, 0.0, 0.0])


def _grid() -> np.ndarray:
    return np.zeros((250, 250), np.uint8)


def _ring(radius_m: float, width_m: float, arc_deg: float = 360.0) -> np.ndarray:
    g = _grid()
    r_px = int(round((radius_m - width_m / 2) / RES))
    cv2.ellipse(g, (125, 125), (r_px, r_px), 0, 0, arc_deg, 1, int(round(width_m / RES)))
    return g.astype(bool)


def test_a_ring_of_a_door_size_is_a_porthole_and_its_box_is_the_door() -> None:
    """A ring 0.44 m across, 5 cm wide (a washing machine's door ring at 4 mm px): one porthole, its box
    the ring's outer square (110 px ± the ring's drawn edge)."""
    boxes = find_portholes(_ring(0.22, 0.05), RES, PortholeConfig())
    assert len(boxes) == 1
    r0, r1, c0, c1 = boxes[0]
    assert abs((r1 - r0) - 110) <= 3 and abs((c1 - c0) - 110) <= 3
    assert abs(0.5 * (r0 + r1) - 125) <= 1.5 and abs(0.5 * (c0 + c1) - 125) <= 1.5


def test_a_ring_broken_in_one_place_is_still_a_porthole_but_half_a_ring_is_not() -> None:
    """The fused ring breaks where the scan missed it: 300 of 360 degrees still reach 20 of 24 sectors
    (0.75 needed: 18); an arc of 180 degrees reaches 12 and is no door (a curved edge, a chair's back)."""
    assert len(find_portholes(_ring(0.22, 0.05, 300.0), RES, PortholeConfig())) == 1
    assert find_portholes(_ring(0.22, 0.05, 180.0), RES, PortholeConfig()) == []


def test_a_filled_disc_a_square_frame_and_a_small_ring_are_no_portholes() -> None:
    """A disc 0.44 m across (a round boss, a clock) is proud inside; a square frame 0.44 m across (a
    glazed door's rails) has its corners at 1.41 of the half side, 43 % of its outline beyond the 1.15
    band; a ring 0.2 m across (a hob's burner ring, a knob's bezel) is smaller than any door."""
    disc = _grid()
    cv2.circle(disc, (125, 125), 55, 1, -1)
    assert find_portholes(disc.astype(bool), RES, PortholeConfig()) == []
    square = _grid()
    cv2.rectangle(square, (70, 70), (180, 180), 1, 12)
    assert find_portholes(square.astype(bool), RES, PortholeConfig()) == []
    assert find_portholes(_ring(0.1, 0.03), RES, PortholeConfig()) == []


def _front(u0: float, u1: float, v0: float, v1: float, handle: bool = False) -> Front:
    c = np.array([0.5 * (u0 + u1), 0.0, 0.5 * (v0 + v1)])
    f = Front(facet=-1, handle_facets=[], center=c, n_out=N.copy(), u=U.copy(), extent_u=(u0, u1), extent_v=(v0, v1))
    if handle:
        f.handle_points = np.array([[u0 + 0.05, 0.0, v1 - 0.05], [u1 - 0.05, 0.0, v1 - 0.05]])
    return f


def test_a_porthole_door_is_hinged_at_a_side_though_it_is_drawer_sized() -> None:
    """A porthole box 0.44 x 0.44 m is as low as a deep drawer (drawer_max_h 0.45) and as wide as tall:
    without a handle the shape rules call it a drawer; a round door is hinged at a side (vertical axis)."""
    door = _front(0.08, 0.52, 0.16, 0.60)
    r = FrontRulesConfig()
    kind, _ = _joint(door, None, [], r)
    assert kind == "drawer"
    kind, art = _joint(door, None, [], r, side_hinged=True)
    assert kind == "door" and joint_class(art) == "revolute_vertical"


def test_the_plate_strips_over_a_porthole_go_and_a_detergent_drawer_beside_it_stays() -> None:
    """A washing machine 0.6 m wide, its door box 0.08-0.52 x 0.16-0.60: the plate's strip right above the
    door (0.61-0.70) and the control strip over it (0.70-0.84, 0.1 m above the door: within plate_gap 0.15)
    span the door's width: plate, with or without a "handle" (its knob, the drawer's edge). The detergent
    drawer (0-0.2 wide, its grip a handle) is narrower; the control panel beside it (0.2-0.6, over the door's
    columns 0.2-0.52) has no handle: plate. A plain front as narrow beside the door's columns (0.53-0.6) is no
    strip of it, nor is a strip 0.3 m above (beyond the gap). The cell covering the whole plate overlaps the
    door by all of its area (0.44 x 0.44 m)."""
    door = _front(0.08, 0.52, 0.16, 0.60)
    gap = PortholeConfig().plate_gap
    assert _plate_strip(_front(0.0, 0.6, 0.61, 0.70), door, gap)
    assert _plate_strip(_front(0.0, 0.6, 0.70, 0.84), door, gap)
    assert _plate_strip(_front(0.2, 0.6, 0.70, 0.84), door, gap)
    assert not _plate_strip(_front(0.53, 0.6, 0.70, 0.84), door, gap)
    assert not _plate_strip(_front(0.0, 0.6, 0.90, 1.10), door, gap)
    assert _plate_strip(_front(0.0, 0.6, 0.70, 0.84, handle=True), door, gap)
    assert not _plate_strip(_front(0.0, 0.2, 0.70, 0.84, handle=True), door, gap)
    assert abs(_overlap(_front(0.0, 0.6, 0.0, 0.84), door) - 0.44 * 0.44) < 1e-9
