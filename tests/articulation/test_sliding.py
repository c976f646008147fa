"""Sliding doors: the refinement keeps an in-plane axis when the predictor says 'sliding',
assembly gives them a travel along their own width, and the heuristic's two-track rule finds them."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.articulation import PartFit, fit_part, refine_articulation
from react3d_core.articulation.refine import refine_sliding
from react3d_core.assembly import sliding_limits
from react3d_core.config.heuristic import SlidingConfig
from react3d_core.data.parts import Articulation
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.sliding import mark_sliding, sliding_partner



def slab(w: float = 0.6, h: float = 0.8, t: float = 0.02, n: int = 2000, seed: int = 0) -> np.ndarray:
    """Points on a door slab: x in [0, w], z in [0, h], y in [0, t] (front face y = 0)."""
    rng = np.random.default_rng(seed)
    p = rng.uniform([0, 0, 0], [w, t, h], (n, 3))
    p[: n // 2, 1] = 0.0
    p[n // 2:, 1] = t
    return p


def _door_fit() -> PartFit:
    """A 0.6 m wide, 0.8 m tall, 2 cm thick slab in the x-z plane (front normal +y into the cavity)."""
    return fit_part(slab(), camera=np.array([0.3, -2.0, 0.4]), plane_normal=(0.0, 1.0, 0.0), flat_ratio=0.5)


def test_sliding_prediction_keeps_the_in_plane_axis() -> None:
    fit = _door_fit()
    assert fit.flat and abs(fit.front_normal[1]) == pytest.approx(1.0, abs=1e-6)
    # predicted: mostly +x (sliding right), 10 deg off towards the normal and 5 deg up
    a = np.array([np.cos(np.radians(10)), np.sin(np.radians(10)), np.sin(np.radians(5))])
    pred = Articulation(joint_type="prismatic", axis=a, origin=(0.3, 0.0, 0.4))
    out = refine_articulation(pred, fit, refine=True, sliding=True)
    np.testing.assert_allclose(out.axis, (1.0, 0.0, 0.0), atol=1e-3)  # the horizontal in-plane OBB side, sign kept
    assert out.origin == pred.origin
    # without the flag the paper's rule pulls it out of the front: 90 deg off
    np.testing.assert_allclose(np.abs(refine_articulation(pred, fit, refine=True).axis), (0.0, 1.0, 0.0), atol=1e-3)
    # sliding left (sign kept), and a vertical predicted motion snaps onto the vertical side
    left = refine_sliding(pred.model_copy(update={"axis": (-1.0, 0.1, 0.0)}), fit.obb)
    np.testing.assert_allclose(left.axis, (-1.0, 0.0, 0.0), atol=1e-3)
    up = refine_sliding(pred.model_copy(update={"axis": (0.1, 0.3, 1.0)}), fit.obb)
    np.testing.assert_allclose(up.axis, (0.0, 0.0, 1.0), atol=1e-3)


def test_sliding_limits_travel_the_width() -> None:
    a = Articulation(joint_type="prismatic", axis=(-1.0, 0.0, 0.0), origin=(0.3, 0.0, 0.4))
    out = sliding_limits(a, slab(), margin=0.02, min_travel=0.05)
    assert out.axis == (-1.0, 0.0, 0.0)  # no cavity test flips it
    assert out.upper == pytest.approx(0.6 - 0.02, abs=1e-3)  # slab spans x in [0, 0.6]
    assert out.limit_source == "sliding"


def _front(x0: float, x1: float, y: float, z0: float = 0.1, z1: float = 0.8) -> Front:
    """A front facing the room (-y) in the wall frame of the synthetic rooms: u = +x, n_out = -y."""
    return Front(facet=0, handle_facets=[], center=np.array([(x0 + x1) / 2, y, (z0 + z1) / 2]),
                 n_out=np.array([0.0, -1.0, 0.0]), u=np.array([1.0, 0.0, 0.0]), extent_u=(x0, x1), extent_v=(z0, z1))


def test_two_track_fronts_are_sliding_doors() -> None:
    outer = _front(0.0, 0.62, -0.055)   # left door on the room-side track
    inner = _front(0.58, 1.2, -0.021)   # right door 3.4 cm behind it, overlapping 4 cm
    coplanar = [_front(1.5, 1.9, -0.021), _front(1.904, 2.3, -0.021)]  # a hinged pair: same plane
    fronts = [outer, inner, *coplanar]
    assert sliding_partner(outer, fronts, SlidingConfig()) is inner
    assert mark_sliding(fronts) == 2
    assert outer.kind == inner.kind == "sliding"
    assert outer.articulation.joint_type == inner.articulation.joint_type == "prismatic"
    np.testing.assert_allclose(outer.articulation.axis, (1.0, 0.0, 0.0))   # towards the other door
    np.testing.assert_allclose(inner.articulation.axis, (-1.0, 0.0, 0.0))
    assert outer.articulation.upper == pytest.approx(0.62 - 0.04)          # width less the overlap
    np.testing.assert_allclose(outer.articulation.origin, (0.31, -0.055, 0.45))
    assert all(f.kind == "" for f in coplanar)


def test_offset_fronts_that_are_not_a_pair() -> None:
    r = SlidingConfig()
    a = _front(0.0, 0.6, -0.055)
    assert sliding_partner(a, [a, _front(0.6, 1.2, -0.021, z1=0.5)], r) is None    # not as tall
    assert sliding_partner(a, [a, _front(0.7, 1.3, -0.021)], r) is None            # 10 cm apart
    assert sliding_partner(a, [a, _front(0.1, 0.5, -0.021)], r) is None            # one inside the other
    assert sliding_partner(a, [a, _front(0.58, 1.2, -0.2)], r) is None             # 14.5 cm behind: another object
    assert sliding_partner(a, [a, _front(0.58, 1.2, -0.052)], r) is None           # coplanar (3 mm)
