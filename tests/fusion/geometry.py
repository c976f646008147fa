"""Hand-made geometry for the fusion tests: flat door grids in front of a wall, posed cameras."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from react3d_core.camera import look_at
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.mesh import TriMesh


def grid(x0: float, x1: float, z0: float, z1: float, y: float, nx: int, nz: int) -> TriMesh:
    """A welded nx x nz grid of quads (2 triangles each) in the plane y = const, facing -y."""
    xs, zs = np.linspace(x0, x1, nx + 1), np.linspace(z0, z1, nz + 1)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], 1)
    idx = np.arange(X.size).reshape(nx + 1, nz + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    f = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return TriMesh(v, f)


def merge(*meshes: TriMesh) -> tuple[TriMesh, list[np.ndarray]]:
    """One mesh from several (no welding); also each input's face ids in it."""
    vs, fs, ids, nv, nf = [], [], [], 0, 0
    for m in meshes:
        vs.append(m.vertices)
        fs.append(m.faces + nv)
        ids.append(np.arange(nf, nf + m.n_faces))
        nv += m.n_vertices
        nf += m.n_faces
    return TriMesh(np.concatenate(vs), np.concatenate(fs)), ids


def two_doors() -> tuple[TriMesh, np.ndarray, np.ndarray]:
    """Two coplanar 0.5 x 0.8 m doors sharing an edge (welded, one grid), 5 cm in front of a wall."""
    doors = grid(0.0, 1.0, 0.0, 0.8, -0.05, 20, 16)
    wall = grid(-1.0, 2.0, -0.5, 1.5, 0.0, 30, 20)
    mesh, (d, _w) = merge(doors, wall)
    cx = mesh.vertices[mesh.faces[d]].mean(1)[:, 0]
    return mesh, d[cx < 0.5], d[cx >= 0.5]


def frames(n: int = 4, width: int = 160, height: int = 120, target=(0.5, 0.0, 0.4)) -> list[Frame]:
    """``n`` cameras ~2 m in front of the doors (negative y), spread sideways and in height."""
    intr = Intrinsics(fx=150.0, fy=150.0, cx=width / 2, cy=height / 2, width=width, height=height)
    out = []
    for i in range(n):
        eye = np.array([0.5 + 0.6 * np.sin(i * 1.3), -2.0, 0.4 + 0.3 * np.cos(i * 0.7)])
        pose = look_at(eye, np.asarray(target, float))
        out.append(Frame(frame_id=f"frame_{i:06d}", rgb=ImageRef(path=Path(f"/nonexistent/{i}.jpg"), kind="jpg"),
                         intrinsics=intr, pose=pose))
    return out
