"""Scan-like meshes for synthetic scenes (``mesh="laser"|"tsdf"``) and ground truth moved onto them.

A generated scene's own mesh is perfect: every front is a separate slab with a 4 mm gap around it and
handles are exact boxes. Real scan meshes are not, and perception tuned on perfect meshes fails on
them. So the written mesh can be re-made the way real scans are:

- ``tsdf``: the scene's own noisy depth frames (256x192, after :func:`.render.sensor_depth`, as
  uint16 mm like ``depth.bin``) and colour frames (the written RGB, area-resized to the depth size)
  fused at 1 cm voxels in an Open3D ``VoxelBlockGrid`` (the legacy ScalableTSDFVolume returns no
  triangles in Open3D 0.20), then marching cubes with vertex colours;
- ``laser``: virtual noise-free range scans from the capture poses at the RGB resolution (960x720:
  2-4 mm between samples at 1.5-3 m), Gaussian range noise of 1.5 mm along each ray, fused at 5 mm
  voxels and extracted, i.e. a 5 mm remesh of the observed surfaces only; marching cubes gives
  ~3.5 mm edges (1.2 M faces for a kitchen), so the mesh is then quadric-decimated to half its faces
  (fast-simplification; ~5 mm edges, flat areas coarser, as scanner software does); vertex colours
  are the clean mesh's colour at the nearest surface point.

Both keep the world frame (z up, metres). Open3D's hash map orders blocks by thread timing, so the
extracted mesh is put in a canonical order (vertices welded and sorted by position, faces sorted):
same seed -> same bytes.

Ground truth transfer: each new vertex takes the part of the nearest point of the clean surface if
it lies within 1 cm (else it is unlabelled), each face the majority of its vertices' parts (none
without a majority). The nearest *surface point* is used rather than the nearest clean *vertex*:
clean meshes have 3-5 cm triangles, so almost no new vertex would be within 1 cm of a clean vertex.
Parts left without vertices or faces are dropped from the GT (listed in ``synth_meta.json``).

Tessellation variants (``decimate``: quadric decimation to a share of the faces; ``cluster_vertices``:
vertex clustering on a voxel grid, the coarse remesh scanner apps export) re-make a finished scan mesh the
way a user's mesh may come: the same surface in other triangles. Perception must give the same answer on
them; ``benchmarks/make_variants.py`` writes them as scene folders, and ``generate_scene(decimate=...)``
decimates a laser / TSDF scene's mesh before its ground truth is transferred.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from ..data.mesh import TriMesh
from ..raster import Rasterizer
from ..ground_truth.articulate3d import GTPart

MESH_KINDS = ("clean", "laser", "tsdf")
TSDF_VOXEL = 0.01
LASER_VOXEL = 0.005
LASER_RANGE_NOISE = 0.0015
LASER_DECIMATION = 0.5
TRANSFER_RADIUS = 0.01


@dataclass
class TsdfFuser:
    """Collects depth (and colour) frames, then fuses them into a mesh with an Open3D VoxelBlockGrid.

    Frames are kept until :meth:`mesh` so the grid can be sized to exactly the blocks they touch
    (a fixed generous capacity costs gigabytes at 5 mm voxels).
    """

    voxel: float
    color: bool = True
    depth_max: float = 6.0
    trunc_voxels: float = 4.0
    block_resolution: int = 8
    weight_threshold: float = 1.0
    depth_scale: float = 1000.0  # depth units per metre in the stored uint16 frames
    _frames: list[tuple[np.ndarray, np.ndarray | None, np.ndarray, np.ndarray]] = field(default_factory=list)

    def add(self, depth_m: np.ndarray, K: np.ndarray, c2w: np.ndarray, rgb: np.ndarray | None = None) -> None:
        """Queue one frame: z-depth in metres (0 / inf / nan = no reading), its K, camera-to-world pose,
        and an RGB uint8 image of any size (resized to the depth image)."""
        d = np.where(np.isfinite(depth_m) & (depth_m > 0) & (depth_m < self.depth_max), depth_m, 0.0)
        d16 = np.clip(np.round(d * self.depth_scale), 0, 65535).astype(np.uint16)
        col = None
        if self.color:
            if rgb is None:
                raise ValueError("this fuser fuses colour: pass rgb")
            h, w = d16.shape
            col = np.ascontiguousarray(cv2.resize(rgb, (w, h), interpolation=cv2.INTER_AREA))
        self._frames.append((d16, col, np.asarray(K, np.float64), np.linalg.inv(np.asarray(c2w, np.float64))))

    def mesh(self) -> TriMesh:
        """Fuse every queued frame and extract the triangle mesh (canonical vertex and face order)."""
        import open3d as o3d
        import open3d.core as o3c

        if not self._frames:
            raise ValueError("no frames to fuse")
        dev = o3c.Device("CPU:0")
        names = ("tsdf", "weight", "color") if self.color else ("tsdf", "weight")
        dtypes = (o3c.float32,) * len(names)
        chans = ((1), (1), (3)) if self.color else ((1), (1))

        def grid(count: int) -> "o3d.t.geometry.VoxelBlockGrid":
            return o3d.t.geometry.VoxelBlockGrid(names, dtypes, chans, self.voxel, self.block_resolution, count, dev)

        probe = grid(16)
        blocks = []
        for d16, _, K, w2c in self._frames:
            bc = probe.compute_unique_block_coordinates(
                o3d.t.geometry.Image(o3c.Tensor(d16)), o3c.Tensor(K), o3c.Tensor(w2c),
                self.depth_scale, self.depth_max, self.trunc_voxels)
            blocks.append(bc.numpy())
        n_blocks = len(np.unique(np.concatenate(blocks), axis=0))
        vbg = grid(int(n_blocks * 1.1) + 64)
        for (d16, col, K, w2c), bc in zip(self._frames, blocks):
            depth = o3d.t.geometry.Image(o3c.Tensor(d16))
            args = (o3c.Tensor(K), o3c.Tensor(w2c), self.depth_scale, self.depth_max, self.trunc_voxels)
            if col is None:
                vbg.integrate(o3c.Tensor(bc), depth, *args)
            else:
                vbg.integrate(o3c.Tensor(bc), depth, o3d.t.geometry.Image(o3c.Tensor(col)), *args)
        m = vbg.extract_triangle_mesh(weight_threshold=self.weight_threshold)
        v = m.vertex.positions.numpy().astype(np.float64)
        f = m.triangle.indices.numpy().astype(np.int64)
        c = m.vertex.colors.numpy() if self.color and "colors" in m.vertex else None
        return canonical_mesh(v, f, c)


def canonical_mesh(v: np.ndarray, f: np.ndarray, colors: np.ndarray | None = None) -> TriMesh:
    """Weld coincident vertices, sort vertices by position and faces lexicographically (keeping each
    face's winding), drop degenerate and duplicate faces: an order that does not depend on threads."""
    if len(v) == 0:
        return TriMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    uv, first, inv = np.unique(v, axis=0, return_index=True, return_inverse=True)
    f = inv.reshape(-1)[f]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    r = np.argmin(f, axis=1)  # rotate so the smallest index comes first (same winding)
    f = np.stack([f[np.arange(len(f)), r], f[np.arange(len(f)), (r + 1) % 3], f[np.arange(len(f)), (r + 2) % 3]], 1)
    f = np.unique(f, axis=0)
    used = np.zeros(len(uv), bool)
    used[f.ravel()] = True
    remap = np.cumsum(used) - 1
    col = None
    if colors is not None:
        col = np.clip(np.round(np.asarray(colors, np.float64)[first] * 255.0), 0, 255).astype(np.uint8)[used]
    return TriMesh(uv[used], remap[f], col)


def decimate(mesh: TriMesh, reduction: float) -> TriMesh:
    """Quadric decimation to ``1 - reduction`` of the faces (colours dropped: set them afterwards)."""
    import fast_simplification

    v, f = fast_simplification.simplify(mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32), reduction)
    return canonical_mesh(np.asarray(v, np.float64), np.asarray(f, np.int64))


def decimate_to(mesh: TriMesh, keep: float) -> TriMesh:
    """Quadric decimation keeping ``keep`` of the faces (0 < keep <= 1) or, with ``keep`` > 1, about
    that many faces; colours taken from the nearest point of the input surface."""
    if keep <= 0:
        raise ValueError(f"decimation must keep a positive share or count of faces, got {keep}")
    share = keep if keep <= 1 else min(1.0, keep / max(mesh.n_faces, 1))
    if share >= 1:
        return mesh
    return recoloured(mesh, decimate(mesh, 1.0 - share))


def cluster_vertices(mesh: TriMesh, voxel: float) -> TriMesh:
    """Vertex clustering on a ``voxel`` grid (Open3D, vertices averaged per cell; faces that collapse
    dropped), colours from the nearest point of the input surface."""
    import open3d as o3d

    if voxel <= 0:
        raise ValueError(f"clustering voxel must be positive, got {voxel}")
    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(mesh.vertices.astype(np.float64)),
                                  o3d.utility.Vector3iVector(mesh.faces.astype(np.int32)))
    c = m.simplify_vertex_clustering(voxel_size=float(voxel))
    out = canonical_mesh(np.asarray(c.vertices, np.float64), np.asarray(c.triangles, np.int64))
    return recoloured(mesh, out)


def recoloured(src: TriMesh, dst: TriMesh) -> TriMesh:
    """``dst`` with each vertex coloured like the nearest point of ``src``'s surface (``dst`` as is when
    ``src`` has no colours)."""
    if src.colors is None or dst.n_vertices == 0:
        return dst
    points, prim, uv = Rasterizer(src).closest_points(dst.vertices.astype(np.float32))
    tri = src.faces[prim]
    cs = src.colors.astype(np.float64)
    col = cs[tri[:, 0]] * (1 - uv[:, :1] - uv[:, 1:]) + cs[tri[:, 1]] * uv[:, :1] + cs[tri[:, 2]] * uv[:, 1:]
    return TriMesh(dst.vertices, dst.faces, np.clip(np.round(col), 0, 255).astype(np.uint8))


def laser_depth(z_depth: np.ndarray, ray_dirs_cam_norm: np.ndarray, rng: np.random.Generator,
                sigma: float = LASER_RANGE_NOISE) -> np.ndarray:
    """A noise-free z-depth image with Gaussian range noise of ``sigma`` metres along each ray.

    ``ray_dirs_cam_norm``: per pixel the length of the camera ray whose z component is 1 (so the ray
    length is ``z * norm``)."""
    eps = rng.normal(0.0, sigma, z_depth.shape).astype(np.float32)
    return np.where(np.isfinite(z_depth), z_depth + eps / ray_dirs_cam_norm, np.inf).astype(np.float32)


@dataclass
class Transfer:
    """Labels moved from the clean mesh onto a new one."""

    vertex_label: np.ndarray  # per new vertex: label of the nearest clean surface point, -1 beyond the radius
    face_label: np.ndarray    # per new face: majority of its vertices' labels, -1 without a majority
    distance: np.ndarray      # per new vertex: distance to the clean surface (m)
    colors: np.ndarray        # per new vertex: the clean colour at the nearest surface point (uint8)


def transfer_labels(src: TriMesh, src_face_label: np.ndarray, dst: TriMesh, radius: float = TRANSFER_RADIUS) -> Transfer:
    """Move per-face labels of ``src`` to the vertices and faces of ``dst`` (see module doc)."""
    q = dst.vertices.astype(np.float32)
    points, prim, uv = Rasterizer(src).closest_points(q)
    dist = np.linalg.norm(points - q, axis=1)
    lab = np.where(dist <= radius, np.asarray(src_face_label)[prim], -1)
    a, b, c = (lab[dst.faces[:, k]] for k in range(3))
    flab = np.where((a == b) | (a == c), a, np.where(b == c, b, -1))
    tri = src.faces[prim]
    cs = src.colors.astype(np.float64)
    col = cs[tri[:, 0]] * (1 - uv[:, :1] - uv[:, 1:]) + cs[tri[:, 1]] * uv[:, :1] + cs[tri[:, 2]] * uv[:, 1:]
    return Transfer(lab.astype(np.int64), flab.astype(np.int64), dist, np.clip(np.round(col), 0, 255).astype(np.uint8))


def transfer_parts(parts: list[GTPart], tr: Transfer, keep_empty_movable: bool = False) -> tuple[list[GTPart], list[int]]:
    """GT parts on the new mesh (same part ids, joints and bases); returns them and the dropped ids.
    ``keep_empty_movable``: a movable part left without vertices or faces stays (empty; its GT box
    scores it), as a front the depth sensor missed still exists."""
    out, dropped = [], []
    for p in parts:
        vert = np.flatnonzero(tr.vertex_label == p.part_id)
        tri = np.flatnonzero(tr.face_label == p.part_id)
        if keep_empty_movable and p.movable and (len(vert) == 0 or len(tri) == 0):
            out.append(GTPart(p.part_id, p.label, tri, vert, p.articulation, list(p.base)))
            continue
        if len(vert) == 0 or len(tri) == 0:
            dropped.append(p.part_id)
            continue
        out.append(GTPart(p.part_id, p.label, tri, vert, p.articulation, list(p.base)))
    kept = {p.part_id for p in out}
    for p in out:
        p.base = [b for b in p.base if b in kept]
    return out, dropped
