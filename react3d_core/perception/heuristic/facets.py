"""Planar facets of a scan mesh: faces joined across shared edges when their normals agree.

Vertices closer than ``weld_m`` are merged first (scans and box-built meshes repeat vertices along
edges). Seams between furniture fronts — gaps of a few millimetres or grooves where the normal
turns — then separate facets, which is what the heuristic backend relies on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ...config.heuristic import FacetConfig
from ...data.mesh import TriMesh
from ...geometry import edge_adjacency


def weld(vertices: np.ndarray, tol: float) -> np.ndarray:
    """Index of the representative of each vertex after snapping to a ``tol`` grid."""
    q = np.round(vertices / tol).astype(np.int64)
    _, inv = np.unique(q, axis=0, return_inverse=True)
    return inv.ravel()


@dataclass
class Facets:
    """``labels[f]`` = facet of face f; per-facet normal (area-weighted) and area."""

    labels: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    welded: np.ndarray  # representative vertex of each vertex

    @property
    def n(self) -> int:
        return len(self.areas)


def planar_facets(mesh: TriMesh, cfg: FacetConfig = FacetConfig()) -> Facets:
    """Split the mesh into facets (see module docstring); fully vectorized. The pipeline passes
    ``perception.heuristic.facets``."""
    rep = weld(mesh.vertices, cfg.weld_m)
    faces = rep[mesh.faces]
    normals, areas = mesh.face_normals, mesh.face_areas
    pairs = edge_adjacency(faces, chain="corner")  # the chain order facets were always built with
    ok = (normals[pairs[:, 0]] * normals[pairs[:, 1]]).sum(1) >= np.cos(np.radians(cfg.max_angle_deg))
    p = pairs[ok]
    g = coo_matrix((np.ones(len(p)), (p[:, 0], p[:, 1])), shape=(len(faces), len(faces)))
    n_lab, labels = connected_components(g, directed=False)
    fa = np.zeros((n_lab, normals.shape[1]))
    np.add.at(fa, labels, normals * areas[:, None])
    area = np.bincount(labels, weights=areas, minlength=n_lab)
    fn = fa / np.maximum(np.linalg.norm(fa, axis=1), 1e-15)[:, None]
    return Facets(labels, fn, area, rep)


def vertex_components(mesh: TriMesh, welded: np.ndarray) -> np.ndarray:
    """Connected component of every face through shared (welded) vertices."""
    f = welded[mesh.faces]
    n = int(welded.max()) + 1 if len(welded) else 0
    rows = np.concatenate([f[:, 0], f[:, 1]])
    cols = np.concatenate([f[:, 1], f[:, 2]])
    g = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, vlab = connected_components(g, directed=False)
    return vlab[f[:, 0]]
