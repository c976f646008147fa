"""Scene assembly: dedup -> cavity -> limits -> carving -> meshes + ``scene.json``.

Background vertices inside any part's OBB (grown by ``obb_margin_m``) are deleted with their faces,
as are the parts' own faces, so a closed part never interpenetrates the background. Each object is
labelled and named from the evidence (``naming``: ``drawer_03``, ``door_01``). Output layout
(docs/CONTRACTS.md section 5)::

    scene.json, meshes/background.ply, meshes/<object_id>/{part,base,inner}.ply, vertex_ids.npz
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..articulation.limits import set_limits, sweep_points
from ..articulation.refine import slab_mid_and_thickness
from ..articulation.types import ArticulatedPart
from ..cavity import PartFrame, base_mesh, estimate_cavity, inner_box_mesh
from ..config import PipelineConfig
from ..data.frames import SceneInput
from ..data.mesh import TriMesh, save_mesh
from ..data.parts import Articulation, InteractiveObject, InteractiveScene, save_vertex_ids
from ..dedup import remove_duplicates
from ..raster import Rasterizer
from .naming import floor_height, object_ids, part_label, spatial_key


class _Geometry:
    """Ray casts and closest-point distances on the scan mesh (its Rasterizer), built once per scene."""

    def __init__(self, mesh: TriMesh) -> None:
        self.raster = Rasterizer(mesh)

    def cast(self, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
        return self.raster.cast_rays(origins, dirs).t

    def distance_excluding(self, own: np.ndarray, front: np.ndarray | None = None, n: np.ndarray | None = None,
                           behind_margin: float = 0.01, with_points: bool = False):  # noqa: ANN201
        """Distance to the scan, ignoring faces flagged in ``own`` (the part and what is attached to it)
        and, given the part's front point and normal ``n`` (into the cavity), geometry that is not at
        least ``behind_margin`` in front of the front plane: the part's own frame (jambs, carcass
        edges) is built with clearance a scan cannot resolve, while what an opening part really hits
        (a side wall, a neighbour that sticks out) stands in the room. ``with_points``: also return the
        closest points (the sweep checks whether the part moves into them or only past them)."""

        def dist(points: np.ndarray) -> np.ndarray:
            cp, face, _ = self.raster.closest_points(points)
            cp = cp.astype(float)
            d = np.linalg.norm(cp - points, axis=1)
            skip = own[face]
            if front is not None and n is not None:
                skip |= (cp - front) @ n > -behind_margin
            d = np.where(skip, np.inf, d)
            return (d, cp) if with_points else d

        return dist


def attached_faces(mesh: TriMesh, p: ArticulatedPart, pf: PartFrame, reach: float = 0.1) -> np.ndarray:
    """Faces that move with the part: its own, and hardware in front of it within its outline
    (a handle the segmentation left out), up to ``reach`` into the room."""
    own = np.zeros(mesh.n_faces, bool)
    own[p.face_ids] = True
    c = mesh.face_centroids - pf.center
    a, b, d = c @ pf.u, c @ pf.v, c @ pf.n
    own |= (np.abs(a) <= pf.su / 2) & (np.abs(b) <= pf.sv / 2) & (d > -reach) & (d < pf.thickness / 2 + 0.002)
    return own


def moving_faces(mesh: TriMesh, own: np.ndarray, p: ArticulatedPart, pf: PartFrame, inset: float = 0.01) -> np.ndarray:
    """The part's faces and, of the other attached faces (``own``), those wholly inside its outline less
    ``inset``: a handle the segmentation left out moves with the part and sweeps with it; the floor or a
    worktop that merely reaches into the outline's edge does not."""
    extra = own.copy()
    extra[p.face_ids] = False
    v = mesh.vertices[mesh.faces[extra]] - pf.center
    inside = ((np.abs(v @ pf.u) <= pf.su / 2 - inset) & (np.abs(v @ pf.v) <= pf.sv / 2 - inset)).all(1)
    out = np.zeros(mesh.n_faces, bool)
    out[p.face_ids] = True
    out[np.flatnonzero(extra)[inside]] = True
    return out


def carve_background(mesh: TriMesh, parts: list[ArticulatedPart], margin: float) -> np.ndarray:
    """Face ids of the background: faces of no part, with no vertex inside a (grown) part OBB."""
    inside = np.zeros(mesh.n_vertices, bool)
    for p in parts:
        inside |= p.obb.contains(mesh.vertices, margin)
    drop = inside[mesh.faces].any(1)
    for p in parts:
        drop[p.face_ids] = True
    return np.flatnonzero(~drop)


def sliding_limits(a: Articulation, points: np.ndarray, margin: float, min_travel: float) -> Articulation:
    """A sliding door keeps its predicted sign (it slides towards the door it overlaps; the cavity test of
    ``set_limits`` cannot tell left from right in the front plane) and travels its own extent along the
    axis less ``margin``: then it covers the neighbour it slid behind or in front of."""
    ax = np.asarray(a.axis, float)
    d = np.asarray(points, float) @ ax
    extent = float(d.max() - d.min()) if len(d) else 0.0
    return a.model_copy(update={"lower": 0.0, "upper": float(max(min_travel, extent - margin)), "limit_source": "sliding"})


def _part_frame(mesh: TriMesh, p: ArticulatedPart) -> PartFrame:
    R = p.obb.R
    pts = mesh.vertices[p.vertex_ids]
    mid, thick = slab_mid_and_thickness(pts, np.asarray(p.obb.center), p.front_normal)
    return PartFrame(mid, R[:, 0], R[:, 1], np.asarray(p.front_normal, float), p.obb.extents[0], p.obb.extents[1], thick)


def assemble_scene(scene: SceneInput, mesh: TriMesh, parts: list[ArticulatedPart], config: PipelineConfig,
                   out_dir: str | Path) -> InteractiveScene:
    """Write the interactive scene into ``out_dir`` and return its manifest."""
    from ..scene_io.images import frame_depth

    out = Path(out_dir)
    parts = remove_duplicates(list(parts), config.dedup, mesh.vertices, mesh.faces)
    geo = _Geometry(mesh)
    bounds = mesh.bounds()
    frames = {f.frame_id: f for f in scene.frames}
    rng = np.random.default_rng(0)
    floor = floor_height(mesh)
    done = []
    for p in sorted(parts, key=lambda p: -len(p.vertex_ids)):
        pf = _part_frame(mesh, p)
        frame = frames.get(p.seg_frame_id or "")
        depth = frame_depth(frame) if frame is not None else None
        d_in, src, terms = estimate_cavity(pf, geo.cast, bounds, frame, depth, config.cavity)
        own = attached_faces(mesh, p, pf)
        moving = moving_faces(mesh, own, p, pf)
        pts = sweep_points(mesh.vertices[np.union1d(p.vertex_ids, mesh.faces[moving].ravel())], 600, rng)
        dist = geo.distance_excluding(own, pf.center - pf.n * pf.thickness / 2, pf.n, with_points=True)
        if p.sliding:
            art = sliding_limits(p.articulation, pts, config.limits.prismatic_margin_m, config.limits.prismatic_min_m)
        else:
            # closed distances: to everything but the part and its handle (the gaps it glides along)
            art = set_limits(p.articulation, pts, pf.n, d_in, dist, config.limits, geo.distance_excluding(moving),
                             body_depth=terms["body"])
        label = part_label(art, pf.center, pf.u, pf.v, pf.su, pf.sv, p.sliding, floor, config.assembly, tag=p.label)
        done.append((p, pf, art, d_in, src, label))
    ids = object_ids([d[-1] for d in done], [d[1].center for d in done])
    objects = []
    for (p, pf, art, d_in, src, label), oid in sorted(zip(done, ids), key=lambda t: (spatial_key(t[0][1].center), t[1])):
        odir = out / "meshes" / oid
        part_mesh, _ = mesh.submesh(p.face_ids)
        save_mesh(odir / "part.ply", part_mesh)
        save_mesh(odir / "base.ply", base_mesh(pf, d_in, config.cavity))
        inner = None
        if art.joint_type == "prismatic" and not p.sliding:
            save_mesh(odir / "inner.ply", inner_box_mesh(pf, d_in, config.cavity, np.array([0.0, 0.0, 1.0])))
            inner = f"meshes/{oid}/inner.ply"
        save_vertex_ids(odir / "vertex_ids.npz", p.vertex_ids)
        objects.append(InteractiveObject(
            object_id=oid, label=label, score=p.score, articulation=art, initial_articulation=p.initial, obb=p.obb,
            front_normal=tuple(pf.n), part_mesh=f"meshes/{oid}/part.ply", base_mesh=f"meshes/{oid}/base.ply",
            inner_mesh=inner, source_vertex_ids=f"meshes/{oid}/vertex_ids.npz", cavity_depth=float(d_in),
            cavity_depth_source=src, top_views=p.top_views, seg_frame_id=p.seg_frame_id))
    bg, _ = mesh.submesh(carve_background(mesh, parts, config.assembly.obb_margin_m))
    save_mesh(out / "meshes" / "background.ply", bg)
    manifest = InteractiveScene(
        scene_id=scene.scene_id, input_mesh=os.path.relpath(Path(scene.mesh_path).resolve(), out.resolve()),
        background_mesh="meshes/background.ply", objects=objects)
    manifest.save(out / "scene.json")
    return manifest
