"""Plausibility of the scan's units: a mesh in millimetres (or depth in another unit than the poses)
otherwise converts "successfully" into 0 parts with no problem reported.

Checked once per run, when the stages first need the mesh: the room's size, and the depth the
sensor measured against the distance of the mesh from the camera in the same frames.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..data.frames import SceneInput
from ..data.mesh import TriMesh
from ..errors import InputError

MAX_EXTENT_M = 100.0
"""Largest plausible extent of an indoor scan (metres); a millimetre room of 5 m measures 5000."""
MIN_EXTENT_M = 0.05
"""Smallest plausible extent: a scan in kilometres (or scaled to a unit cube) is smaller."""
RATIO_LIMITS = (0.1, 10.0)
"""Accepted median(sensor depth) / median(mesh depth in view); unit errors are 100x-1000x off."""


def _units_hint(factor: float) -> str:
    for name, f in (("millimetres", 1000.0), ("centimetres", 100.0), ("inches", 39.37)):
        if 0.5 * f <= factor <= 2.0 * f:
            return f"; it looks like {name}: convert the mesh to metres (scale by {1 / f:g})"
    return "; convert the mesh to metres"


def depth_mesh_ratio(scene: SceneInput, mesh: TriMesh, max_frames: int = 5, max_vertices: int = 20000) -> float | None:
    """median(valid sensor depth) / median(camera-frame depth of the mesh vertices in view), over up to
    ``max_frames`` frames with depth; None when no frame has both (no depth, or mesh out of view)."""
    from .images import frame_depth

    frames = [f for f in scene.frames if f.depth is not None and f.depth_intrinsics is not None]
    if not frames or len(mesh.vertices) == 0:
        return None
    rng = np.random.default_rng(0)
    v = mesh.vertices
    if len(v) > max_vertices:
        v = v[rng.choice(len(v), max_vertices, replace=False)]
    sensor, model = [], []
    for f in frames[:: max(1, len(frames) // max_frames)][:max_frames]:
        d = frame_depth(f)
        valid = d[d > 0]
        k = f.depth_intrinsics
        w2c = np.linalg.inv(f.pose)
        pc = v @ w2c[:3, :3].T + w2c[:3, 3]
        z = pc[:, 2]
        front = z > 1e-6
        u = k.fx * pc[front, 0] / z[front] + k.cx
        vv = k.fy * pc[front, 1] / z[front] + k.cy
        inside = (u >= 0) & (u < k.width) & (vv >= 0) & (vv < k.height)
        if valid.size < 100 or inside.sum() < 50:
            continue
        sensor.append(float(np.median(valid)))
        model.append(float(np.median(z[front][inside])))
    if not sensor:
        return None
    return float(np.median(sensor)) / max(float(np.median(model)), 1e-12)


def check_scale(scene: SceneInput, mesh: TriMesh, mesh_path: str | Path | None = None) -> None:
    """Raise one :class:`InputError` naming the mesh when the scan's units are implausible."""
    path = Path(mesh_path or scene.mesh_path)
    if len(mesh.vertices) == 0:
        return
    extent = float(np.max(np.ptp(mesh.vertices, axis=0)))
    if extent > MAX_EXTENT_M:
        raise InputError(path, f"mesh spans {extent:.0f} units, implausible for a room in metres (> {MAX_EXTENT_M:.0f} m)"
                               + _units_hint(extent / 5.0))
    if extent < MIN_EXTENT_M:
        raise InputError(path, f"mesh spans {extent:.3g} units, implausible for a room in metres (< {MIN_EXTENT_M} m); "
                               "convert the mesh to metres")
    ratio = depth_mesh_ratio(scene, mesh)
    if ratio is not None and not RATIO_LIMITS[0] <= ratio <= RATIO_LIMITS[1]:
        raise InputError(path, f"the depth frames measure {ratio:.3g}x the mesh's distance from the cameras: the mesh, "
                               "the poses and the depth must all be in metres" + _units_hint(1.0 / ratio))
