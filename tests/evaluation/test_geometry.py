"""Hand-computed cases for the joint geometry metrics."""

import numpy as np
import pytest

from react3d_core.data.parts import Articulation
from react3d_core.metrics import axis_error_deg, joint_class, line_distance


def test_line_distance_skew_lines():
    # x-axis through origin vs a line along y through (0,0,2): distance 2
    assert line_distance([0, 0, 0], [1, 0, 0], [5, 3, 2], [0, 1, 0]) == pytest.approx(2.0)


def test_line_distance_parallel_lines():
    # two z-parallel lines through (0,0) and (3,4): distance 5, independent of the points along z
    assert line_distance([0, 0, 0], [0, 0, 1], [3, 4, 7], [0, 0, -1]) == pytest.approx(5.0)


def test_line_distance_intersecting_is_zero():
    assert line_distance([0, 0, 0], [1, 0, 0], [2, -1, 0], [0, 1, 0]) == pytest.approx(0.0)


def test_axis_error_sign_agnostic_and_value():
    assert axis_error_deg([0, 0, 1], [0, 0, -1]) == pytest.approx(0.0, abs=1e-6)
    assert axis_error_deg([1, 0, 0], [1, 1, 0]) == pytest.approx(45.0)
    assert axis_error_deg([1, 0, 0], [-1, 1, 0]) == pytest.approx(45.0)  # 135 deg folds to 45
    assert axis_error_deg([1, 0, 0], [0, 1, 0]) == pytest.approx(90.0)


def _rev(elev_deg: float) -> Articulation:
    e = np.radians(elev_deg)
    return Articulation(joint_type="revolute", axis=[np.cos(e), 0, np.sin(e)], origin=[0, 0, 0])


def test_joint_class_boundary_at_45_deg():
    assert joint_class(_rev(0)) == "revolute_horizontal"
    assert joint_class(_rev(44.9)) == "revolute_horizontal"
    assert joint_class(_rev(45.1)) == "revolute_vertical"
    assert joint_class(_rev(-44.9)) == "revolute_horizontal"  # downward axis, same elevation
    assert joint_class(_rev(90)) == "revolute_vertical"
    assert joint_class(Articulation(joint_type="prismatic", axis=[0, 0, 1], origin=[0, 0, 0])) == "prismatic"
