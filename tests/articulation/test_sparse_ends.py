"""The part's box ends where its surface does: a sliver triangle bridging the seam to a neighbour does not
stretch the box (and with it the hinge and the cavity) over that neighbour."""

from __future__ import annotations

import numpy as np
import trimesh

from react3d_core.articulation.candidate import fit_part, refine_articulation
from react3d_core.articulation.obb import dense_span, min_obb, surface_samples, trim_sparse_ends
from react3d_core.data.parts import Articulation

# a flap front 0.66 wide (x), 0.54 tall (z), 2 cm thick (y), its bottom edge at z = 0.17
W, H, T, Z0 = 0.66, 0.54, 0.02, 0.17


def front_triangles(subdivisions: int = 3) -> np.ndarray:
    box = trimesh.creation.box(extents=(W, T, H))
    box.apply_translation((0.0, 0.0, Z0 + H / 2))
    v, f = box.vertices, box.faces
    for _ in range(subdivisions):
        v, f = trimesh.remesh.subdivide(v, f)
    return np.asarray(v)[np.asarray(f)]


def sliver(drop: float, x: float = -W / 2, width: float = 0.01) -> np.ndarray:
    """A thin triangle from the front's bottom corner down ``drop`` m (a mask edge taking a seam triangle)."""
    y = -T / 2
    return np.array([[[x, y, Z0], [x + width, y, Z0], [x, y, Z0 - drop]]])


def z_range(obb) -> tuple[float, float]:  # noqa: ANN001
    c = np.asarray(obb.center)
    corners = np.array([[i, j, k] for i in (-0.5, 0.5) for j in (-0.5, 0.5) for k in (-0.5, 0.5)]) * np.asarray(obb.extents)
    w = c + corners @ obb.R.T
    return float(w[:, 2].min()), float(w[:, 2].max())


def test_surface_samples_follow_area_not_vertices() -> None:
    # two triangles of a unit square, one split into many small ones: samples still split ~50/50
    big = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0]]], float)
    small = np.array([[[0, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    v, f = trimesh.remesh.subdivide(small[0], np.array([[0, 1, 2]]))
    for _ in range(3):
        v, f = trimesh.remesh.subdivide(v, f)
    tris = np.concatenate([big, np.asarray(v)[np.asarray(f)]])
    p = surface_samples(tris, 20000, np.random.default_rng(1))
    share = float(np.mean(p[:, 0] > p[:, 1]))  # below the diagonal: the big triangle
    assert abs(share - 0.5) < 0.02
    assert np.array_equal(p, surface_samples(tris, 20000, np.random.default_rng(1)))  # seeded


def test_dense_span_hand_made() -> None:
    # 1000 samples evenly on [0, 1], 3 on [-0.1, 0): 2 cm bins, the sparse ones below 0 drop out
    x = np.concatenate([np.linspace(0, 1, 1000), [-0.1, -0.06, -0.02]])
    lo, hi = dense_span(x, 0.02, 0.1)
    assert abs(lo - 0.0) <= 0.02 and hi == 1.0


def test_a_sliver_below_a_flap_is_cut_off_its_box() -> None:
    tris = np.concatenate([front_triangles(), sliver(0.1)])
    full = min_obb(tris.reshape(-1, 3))
    assert z_range(full)[0] < Z0 - 0.09  # the vertices' box reaches 10 cm down over the neighbour
    trimmed = trim_sparse_ends(full, tris, 0.1, 0.02)
    lo, hi = z_range(trimmed)
    assert abs(lo - Z0) <= 0.006 and abs(hi - (Z0 + H)) <= 1e-6
    assert np.allclose(sorted(trimmed.extents), [T, H, W], atol=0.006)  # width and thickness kept
    assert abs(max(trimmed.extents) - W) < 1e-6 and abs(min(trimmed.extents) - T) < 1e-6


def test_a_plain_front_keeps_its_box_however_coarse_its_mesh() -> None:
    for sub in (0, 4):  # 12 triangles, or thousands
        tris = front_triangles(sub)
        obb = min_obb(tris.reshape(-1, 3))
        assert trim_sparse_ends(obb, tris, 0.1, 0.02) == obb


def test_a_short_sparse_end_and_a_handle_stay() -> None:
    tris = np.concatenate([front_triangles(), sliver(0.015)])  # under the 2 cm minimum
    obb = min_obb(tris.reshape(-1, 3))
    assert trim_sparse_ends(obb, tris, 0.1, 0.02) == obb
    # a bar handle 3 cm proud of the front (along the thickness axis) is never trimmed
    handle = trimesh.creation.box(extents=(0.3, 0.03, 0.02))
    handle.apply_translation((0.0, -T / 2 - 0.015, Z0 + H - 0.05))
    tris = np.concatenate([front_triangles(), np.asarray(handle.vertices)[np.asarray(handle.faces)]])
    obb = min_obb(tris.reshape(-1, 3))
    assert trim_sparse_ends(obb, tris, 0.1, 0.02) == obb


def test_the_flap_hinge_lands_on_its_own_bottom_edge_not_on_the_sliver() -> None:
    tris = np.concatenate([front_triangles(), sliver(0.1)])
    pts = np.unique(tris.reshape(-1, 3), axis=0)
    camera = np.array([0.0, -2.0, 0.5])
    initial = Articulation(joint_type="revolute", axis=(1.0, 0.0, 0.0), origin=(0.0, 0.0, Z0 + 0.02), lower=0.0, upper=0.0)
    plain = refine_articulation(initial, fit_part(pts, camera, (0.0, 1.0, 0.0), 0.5))
    assert plain.origin[2] < Z0 - 0.09  # without the trim: the hinge 10 cm low, in front of the neighbour
    fit = fit_part(pts, camera, (0.0, 1.0, 0.0), 0.5, triangles=tris, sparse_end=(0.1, 0.02))
    art = refine_articulation(initial, fit)
    assert abs(art.origin[2] - Z0) <= 0.006


def tilted_box(angle_deg: float) -> tuple[np.ndarray, "OBB"]:  # noqa: F821
    """A drawer front 1.0 wide (y), 0.19 tall, 2 cm thick facing -x, and the box of it rotated ``angle_deg``
    about the width axis (what a stray triangle reaching behind one corner made the smallest)."""
    from react3d_core.data.parts import OBB

    g = np.random.default_rng(0)
    pts = np.stack([g.uniform(-0.01, 0.01, 3000), g.uniform(-0.5, 0.5, 3000), g.uniform(0.35, 0.54, 3000)], 1)
    a = np.radians(angle_deg)
    n = np.array([np.cos(a), 0.0, -np.sin(a)])
    up = np.array([np.sin(a), 0.0, np.cos(a)])
    R = np.stack([[0.0, 1.0, 0.0], up, n])  # rows s1 (width), s2, s3 (normal)
    local = pts @ R.T
    lo, hi = local.min(0), local.max(0)
    return pts, OBB(center=tuple(((lo + hi) / 2) @ R), axes=tuple(map(tuple, R)), extents=tuple(hi - lo))


def test_a_vertical_clipping_plane_makes_a_tilted_box_upright() -> None:
    from react3d_core.articulation.upright import upright_box

    pts, tilted = tilted_box(16.0)
    # no plane: the 16-degree box is beyond the tilt the volume rule considers, so it stays (the failure)
    assert upright_box(pts, tilted, 0.1) == tilted
    up = upright_box(pts, tilted, 0.1, plane_normal=(1.0, 0.0, 0.0))
    assert abs(up.R[2, 2]) < 1e-9 and abs(abs(up.R[0, 2]) - 1) < 1e-9  # normal horizontal, along the plane's
    assert abs(up.extents[2] - 0.02) < 1e-3 and abs(up.extents[1] - 0.19) < 2e-3
    # a plane that leans (10 degrees) is no evidence of a vertical front: the box stays
    lean = (np.cos(np.radians(10)), 0.0, -np.sin(np.radians(10)))
    assert upright_box(pts, tilted, 0.1, plane_normal=lean) == tilted
    # a box already along the plane (2 degrees off) is left to the volume rule, and tolerance 0 is the paper's box
    pts2, near = tilted_box(2.0)
    assert upright_box(pts2, near, 0.0, plane_normal=(1.0, 0.0, 0.0)) == near
