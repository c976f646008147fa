"""Lifted masks -> 3D part proposals: co-occurrence graph, Louvain, size and connectivity filters.

Fusion may run on a decimated copy of the scan (``config.fusion.decimate_faces``): every scan face
maps to the decimated face with the nearest centroid, lifted faces are mapped through it, and a
community maps back to all scan faces whose nearest decimated face is in it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..config import PipelineConfig
from ..data.mesh import TriMesh
from ..geometry import edge_adjacency, iou_matrix
from .connectivity import largest_component, welded_faces
from .graph import cooccurrence, face_graph, louvain, membership
from .lift import FrameLift


@dataclass
class Proposal:
    """A fused 3D proposal: scan faces (full resolution), Louvain resolution and support (masks)."""

    proposal_id: int
    face_ids: np.ndarray
    resolution: float
    support: int


@dataclass
class FusionMesh:
    """The mesh fusion runs on, with the scan-face -> fusion-face map and welded connectivity."""

    mesh: TriMesh
    face_map: np.ndarray  # scan face -> fusion face
    wfaces: np.ndarray  # fusion faces over welded vertex labels
    adjacency: np.ndarray  # (E,2) edge-adjacent fusion faces

    @property
    def n_faces(self) -> int:
        return self.mesh.n_faces


def decimate(mesh: TriMesh, target_faces: int) -> tuple[TriMesh, np.ndarray]:
    """Vertex-clustering decimation (Open3D) to about ``target_faces``; scan faces map to the
    decimated face with the nearest centroid.

    Why clustering and not quadric error: on a 400k-face scan quadric decimation alone took 6 s,
    clustering well under 1 s; fusion only needs nodes of roughly even size, not a faithful surface.
    The voxel comes from the area: a grid of voxel v has about 2 A / v^2 triangles.
    """
    import open3d as o3d

    area = mesh.face_areas.sum()
    voxel = float(np.sqrt(2.0 * area / max(1, target_faces)))
    m = mesh.to_open3d()
    for _ in range(3):
        small = m.simplify_vertex_clustering(voxel, o3d.geometry.SimplificationContraction.Average)
        n = len(small.triangles)
        if 0.7 * target_faces <= n <= 1.2 * target_faces:
            break
        voxel *= float(np.sqrt(n / target_faces))
    small = TriMesh(np.asarray(small.vertices), np.asarray(small.triangles))
    _, fmap = cKDTree(small.face_centroids).query(mesh.face_centroids, workers=-1)
    return small, fmap.astype(np.int64)


def prepare_fusion_mesh(mesh: TriMesh, config: PipelineConfig) -> FusionMesh:
    """Decimate when the scan is larger than ``decimate_faces``, weld, and build face adjacency."""
    target = config.fusion.decimate_faces
    if target is not None and mesh.n_faces > target:
        small, fmap = decimate(mesh, target)
    else:
        small, fmap = mesh, np.arange(mesh.n_faces, dtype=np.int64)
    wf = welded_faces(small, config.fusion.weld_m)
    return FusionMesh(small, fmap, wf, edge_adjacency(wf))


def _distinct(comms: Sequence[np.ndarray], same: float) -> list[int]:
    """Indices of communities to keep: a community found again (Jaccard > ``same``) is dropped."""
    if not comms:
        return []
    dup = np.tril(iou_matrix(list(comms)) > same, -1).any(1)  # a later one duplicates an earlier one
    return [i for i in range(len(comms)) if not dup[i]]


def fuse_proposals(lifts: Sequence[FrameLift], mesh: TriMesh, config: PipelineConfig, fusion_mesh: FusionMesh | None = None) -> list[Proposal]:
    """Co-occurrence graph of the lifted faces -> Louvain communities at each resolution -> proposals.

    A community is kept when it has more than ``min_community_faces`` fusion faces; it is cut to its
    largest connected component; communities found again at another resolution are merged.
    """
    fc = config.fusion
    fm = fusion_mesh or prepare_fusion_mesh(mesh, config)
    sets = [np.unique(fm.face_map[s]) for lf in lifts for s in lf.face_sets]
    sets = [s for s in sets if len(s)]
    if not sets:
        return []
    n = fm.n_faces
    counts = cooccurrence(sets, n, fm.adjacency, fc.max_pairs_per_mask, fc.seed, fc.max_anchors)
    graph = face_graph(counts, fc.min_cooccurrence)
    M = membership(sets, n)
    support = np.asarray(M.sum(0)).ravel()
    # a face in fewer masks than min_cooccurrence can have no edge; faces with equal mask sets
    # co-occur in all of them (a clique of the exact co-occurrence graph) and are contracted
    nodes = np.nonzero(support >= max(1, fc.min_cooccurrence))[0]
    if not len(nodes):
        return []
    rng = np.random.default_rng(fc.seed)
    sig = (M[:, nodes].T @ rng.random(M.shape[0])).astype(np.float64)
    sig = np.round(sig * 1e9).astype(np.int64)  # equal mask sets -> equal signature
    comms = louvain(graph, nodes, sig, fc.resolutions, fc.seed)
    kept: list[tuple[float, np.ndarray]] = []
    for res, com in comms:
        if len(com) <= fc.min_community_faces:
            continue
        com = largest_component(fm.mesh, fm.wfaces, com, keep_share=fc.keep_share)
        if len(com) > fc.min_community_faces:
            kept.append((res, com))
    out: list[Proposal] = []
    for i in _distinct([c for _, c in kept], fc.distinct_jaccard):
        res, com = kept[i]
        in_com = np.zeros(n, bool)
        in_com[com] = True
        faces = np.nonzero(in_com[fm.face_map])[0]
        out.append(Proposal(len(out), faces, res, int(np.median(support[com]))))
    return out
