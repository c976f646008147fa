"""A chest freezer's front with a bar at its top is typed a drop door by the image rules; it is the lid's
lip, and the lid is the chest's top. Hand-made chests: the front at y = 0 facing -y (u = +x), 1.0 m wide,
0.85 m tall, the top 0.65 m deep."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config.heuristic import LidConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic.fronts import Front
from react3d_core.perception.heuristic.lids import chest_lids

N = np.array([0.0, -1.0, 0.0])
U = np.array([1.0, 0.0, 0.0])


def _grid(a0: float, a1: float, b0: float, b1: float, point, normal: np.ndarray, step: float = 0.02):  # noqa: ANN001, ANN202
    """Vertices and faces of a grid sheet, point(a, b) -> xyz, wound to face ``normal``."""
    A, B = np.meshgrid(np.arange(a0, a1 + 1e-9, step), np.arange(b0, b1 + 1e-9, step))
    v = np.array([point(a, b) for a, b in zip(A.ravel(), B.ravel())])
    na = A.shape[1]
    i = (np.arange(A.shape[0] - 1)[:, None] * na + np.arange(na - 1)[None]).ravel()
    f = np.concatenate([np.stack([i, i + 1, i + na + 1], 1), np.stack([i, i + na + 1, i + na], 1)])
    e1, e2 = v[f[0, 1]] - v[f[0, 0]], v[f[0, 2]] - v[f[0, 0]]
    if np.cross(e1, e2) @ normal < 0:
        f = f[:, ::-1]
    return v, f


def _mesh(*sheets) -> TriMesh:  # noqa: ANN002
    off = np.cumsum([0] + [len(v) for v, _ in sheets[:-1]])
    v = np.concatenate([s[0] for s in sheets])
    return TriMesh(v, np.concatenate([s[1] + o for s, o in zip(sheets, off)]), np.full((len(v), 3), 200, np.uint8))


def _chest(top_x: tuple[float, float] = (0.0, 1.0), top_z: float = 0.85) -> TriMesh:
    front = _grid(0.0, 1.0, 0.04, 0.84, lambda a, b: (a, 0.0, b), N)
    top = _grid(top_x[0], top_x[1], 0.0, 0.64, lambda a, b: (a, b, top_z), np.array([0.0, 0.0, 1.0]))
    return _mesh(front, top)


def _drop(w: float = 1.0, kind: str = "drop") -> Front:
    f = Front(facet=-1, handle_facets=[], center=np.array([w / 2, 0.0, 0.44]), n_out=N.copy(), u=U.copy(),
              extent_u=(0.0, w), extent_v=(0.04, 0.84))
    f.kind = kind
    return f


def _front_faces(mesh: TriMesh) -> np.ndarray:
    return np.flatnonzero(np.abs(mesh.face_centroids[:, 1]) < 1e-6)


def test_a_chest_front_with_a_bar_at_its_top_becomes_the_lid() -> None:
    mesh = _chest()
    f = _drop()
    f.faces = _front_faces(mesh)
    assert chest_lids([f], mesh, LidConfig(), 80.0) == [0]
    assert f.kind == "lid"
    c = mesh.face_centroids[f.faces]
    top = mesh.face_normals[f.faces, 2] > 0.9
    assert top.sum() == (mesh.face_normals[:, 2] > 0.9).sum()          # the whole top
    assert c[~top, 2].min() > 0.85 - 0.08                               # and the lip, no lower
    j = f.articulation
    assert j.joint_type == "revolute"
    assert np.allclose(j.axis, [-1.0, 0.0, 0.0])                        # N x z
    # the hinge runs along the top's back edge (faces' centroids reach 0.63-0.64 m back)
    assert j.origin[1] == pytest.approx(0.63, abs=0.02) and j.origin[2] == pytest.approx(0.85, abs=0.01)
    assert j.upper == pytest.approx(np.radians(80.0))
    # opening lifts the front edge: d/dq of (axis x (edge - origin)) points up
    edge = np.array([0.5, 0.0, 0.85])
    assert np.cross(j.axis, edge - np.asarray(j.origin))[2] > 0


def test_drop_doors_stay_drop_doors() -> None:
    rules = LidConfig()
    under_worktop = _chest(top_x=(-0.6, 1.6))                           # the top runs on past both sides
    assert chest_lids([_drop()], under_worktop, rules, 80.0) == []
    narrow = _drop(0.6)                                                 # dishwasher / oven width
    assert chest_lids([narrow], _chest(top_x=(0.0, 0.6)), rules, 80.0) == []
    assert narrow.kind == "drop"
    below_a_panel = _chest(top_z=0.99)                                  # the top 15 cm above its top edge
    assert chest_lids([_drop()], below_a_panel, rules, 80.0) == []
    assert chest_lids([_drop(kind="door")], _chest(), rules, 80.0) == []
    assert chest_lids([_drop()], _chest(), LidConfig(enabled=False), 80.0) == []
