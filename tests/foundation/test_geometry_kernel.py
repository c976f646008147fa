"""The geometry kernel (react3d_core.geometry, cached on TriMesh) on hand-made meshes, hand-computed."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from react3d_core import geometry
from react3d_core.data.mesh import TriMesh


def unit_square() -> TriMesh:
    """Unit square in z = 0, two counter-clockwise triangles seen from +z, sharing the diagonal 0-2."""
    return TriMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])


def tetrahedron() -> TriMesh:
    """Corner tetrahedron (0,0,0), e_x, e_y, e_z with outward-facing faces."""
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    return TriMesh(v, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_unit_square_normals_areas_centroids_adjacency():
    m = unit_square()
    assert np.array_equal(m.face_cross, [[0, 0, 1], [0, 0, 1]])
    assert np.array_equal(m.face_normals, [[0, 0, 1], [0, 0, 1]])
    assert np.array_equal(m.face_areas, [0.5, 0.5])
    assert np.allclose(m.face_centroids, [[2 / 3, 1 / 3, 0], [1 / 3, 2 / 3, 0]])
    assert m.edge_adjacency.tolist() == [[0, 1]]  # only the diagonal is shared
    assert np.array_equal(m.vertex_normals, [[0, 0, 1]] * 4)


def test_tetrahedron_normals_areas_adjacency():
    m = tetrahedron()
    s = 1 / np.sqrt(3)
    assert np.allclose(m.face_normals, [[0, 0, -1], [0, -1, 0], [-1, 0, 0], [s, s, s]])
    assert np.allclose(m.face_areas, [0.5, 0.5, 0.5, np.sqrt(3) / 2])  # slanted face: |(-1,1,0) x (-1,0,1)| / 2
    # closed surface: every face shares an edge with every other one, and the areas' vector sum is 0
    assert m.edge_adjacency.tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]
    assert np.allclose((m.face_normals * m.face_areas[:, None]).sum(0), 0)
    # vertex 0 touches the three axis faces: normal along -(1,1,1)
    assert np.allclose(m.vertex_normals[0], [-s, -s, -s])


def test_cache_computed_once_read_only_and_dropped_on_new_geometry():
    m = unit_square()
    n = m.face_normals
    assert m.face_normals is n and m.face_areas is m.face_areas
    with pytest.raises(ValueError):
        n[0, 0] = 1.0
    m.vertices = m.vertices * 2.0  # assigning geometry drops the cache
    assert np.array_equal(m.face_areas, [2.0, 2.0])
    m.faces = m.faces[:, ::-1].copy()  # flipped winding: normals flip
    assert np.array_equal(m.face_normals, [[0, 0, -1], [0, 0, -1]])
    back = pickle.loads(pickle.dumps(m))
    assert not ({"face_normals", "face_areas", "face_cross"} & set(vars(back)))  # cache not pickled
    assert np.array_equal(back.face_areas, [2.0, 2.0])


def test_degenerate_face_gets_no_made_up_normal():
    m = TriMesh([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, 1, 3]])
    assert np.array_equal(m.face_normals[0], [0, 0, 0]) and m.face_areas[0] == 0.0
    assert np.array_equal(m.face_normals[1], [0, 0, 1])


def test_raw_array_functions_match_the_cached_ones():
    m = tetrahedron()
    assert np.array_equal(geometry.triangle_cross(m.vertices, m.faces), m.face_cross)
    assert np.array_equal(geometry.triangle_areas(m.vertices, m.faces), m.face_areas)
    assert np.array_equal(geometry.unit_normals(m.face_cross), m.face_normals)
    assert geometry.triangle_cross(m.vertices, np.zeros((0, 3), np.int64)).shape == (0, 3)
    assert geometry.edge_adjacency(np.zeros((0, 3), np.int64)).shape == (0, 2)


def test_edge_adjacency_non_manifold_chains():
    # three triangles on the edge 0-1 (a fin) and one more on edge 1-2 of face 2
    faces = np.array([[0, 1, 2], [1, 0, 3], [4, 0, 1], [1, 4, 5]])
    # by face id: the faces on edge 0-1 are 0, 1, 2 -> chain 0-1, 1-2; face 3 shares 1-4 with face 2
    assert geometry.edge_adjacency(faces).tolist() == [[0, 1], [1, 2], [2, 3]]
    # by corner slot: face 0 has 0-1 at slot (0,1), face 1 at slot (0,1), face 2 at slot (1,2) -> 0-1, 1-2
    assert geometry.edge_adjacency(faces, chain="corner").tolist() == [[0, 1], [1, 2], [2, 3]]
    # a case where the orders differ: face 0 holds 0-1 in slot (1,2), faces 1 and 2 in slot (0,1)
    faces = np.array([[2, 1, 0], [0, 1, 3], [1, 0, 4]])
    assert geometry.edge_adjacency(faces).tolist() == [[0, 1], [1, 2]]
    assert geometry.edge_adjacency(faces, chain="corner").tolist() == [[0, 2], [1, 2]]
    with pytest.raises(ValueError):
        geometry.edge_adjacency(faces, chain="other")


def test_edge_adjacency_ignores_a_face_welded_onto_itself():
    # after welding, a sliver can repeat a vertex: its two edges 0-1 are not a pair with itself
    assert geometry.edge_adjacency(np.array([[0, 1, 1], [1, 0, 2]])).tolist() == [[0, 1]]


# --- vertex-set IoU ------------------------------------------------------------------------------

def test_vertex_iou_hand_values():
    assert geometry.vertex_iou(np.array([0, 1, 2, 3]), np.array([2, 3, 4])) == 2 / 5
    assert geometry.vertex_iou(np.array([0, 0, 1]), np.array([1, 1])) == 1 / 2  # ids deduplicated
    assert geometry.vertex_iou(np.array([7]), np.array([7])) == 1.0
    assert geometry.vertex_iou(np.array([1, 2]), np.zeros(0, np.int64)) == 0.0
    assert geometry.vertex_iou(np.zeros(0, np.int64), np.zeros(0, np.int64)) == 0.0  # empty vs empty: 0


def test_iou_matrix_many_vs_many_hand_values():
    a = [np.arange(0, 10), np.arange(5, 15), np.zeros(0, np.int64)]
    b = [np.arange(0, 10), np.arange(20, 30), np.array([14, 14, 3])]
    # a1 & b0 = 5..9 (5), union 0..14 (15); a1 & b2 = {14} (1), union 5..14 + 3 (11); a0 & b2 = {3}: 1/11
    want = [[1.0, 0.0, 1 / 11], [5 / 15, 0.0, 1 / 11], [0.0, 0.0, 0.0]]
    assert np.array_equal(geometry.iou_matrix(a, b), want)
    inter, sa, sb = geometry.overlap_counts(a, b)
    assert inter.tolist() == [[10, 0, 1], [5, 0, 1], [0, 0, 0]]
    assert sa.tolist() == [10, 10, 0] and sb.tolist() == [10, 10, 2]


def test_iou_matrix_against_itself_and_empty_inputs():
    sets = [np.array([1, 2, 3]), np.array([3, 4]), np.array([10**12])]  # huge ids: compacted, not n columns
    inter, size, size_b = geometry.overlap_counts(sets)
    assert inter.tolist() == [[3, 1, 0], [1, 2, 0], [0, 0, 1]] and size.tolist() == size_b.tolist() == [3, 2, 1]
    assert np.array_equal(geometry.iou_matrix(sets), [[1, 1 / 4, 0], [1 / 4, 1, 0], [0, 0, 1]])
    assert geometry.iou_matrix([], sets).shape == (0, 3)
    assert geometry.iou_matrix(sets, []).shape == (3, 0)
    assert geometry.iou_matrix([np.zeros(0, np.int64)], [np.zeros(0, np.int64)]).tolist() == [[0.0]]


def test_iou_matrix_agrees_with_pairwise_vertex_iou():
    rng = np.random.default_rng(3)
    sets = [rng.integers(0, 60, rng.integers(0, 30)) for _ in range(12)]
    m = geometry.iou_matrix(sets[:5], sets[5:])
    assert np.array_equal(m, [[geometry.vertex_iou(a, b) for b in sets[5:]] for a in sets[:5]])


def test_concat_meshes_offsets_faces_and_horizontal_right():
    sq, tet = unit_square(), tetrahedron()
    v, f = geometry.concat_meshes([(sq.vertices, sq.faces), (tet.vertices, tet.faces)])
    assert v.shape == (8, 3) and f.tolist() == sq.faces.tolist() + (tet.faces + 4).tolist()
    # facing a wall whose normal points back at the viewer along -y, the right is +x
    assert np.allclose(geometry.horizontal_right(np.array([0.0, -1.0, 0.0])), [1, 0, 0])
    assert np.allclose(geometry.horizontal_right(np.array([2.0, 0.0, 0.0])), [0, 1, 0])


def test_weighted_median_by_hand():
    from react3d_core.geometry import weighted_median

    # sorted values 1, 2, 10 with weights 1, 1, 3: cumulative 1, 2, 5 reach half of 5 (2.5) at 10
    assert weighted_median(np.array([10.0, 1.0, 2.0]), np.array([3.0, 1.0, 1.0])) == 10.0
    # weights 2, 1, 1: cumulative 2 reaches half of 4 at the first value (the lower one on a tie)
    assert weighted_median(np.array([10.0, 1.0, 2.0]), np.array([1.0, 2.0, 1.0])) == 1.0
    assert weighted_median(np.array([0.5]), np.array([0.0])) == 0.5
