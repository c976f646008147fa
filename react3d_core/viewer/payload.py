"""The data a browser viewer needs, as one JSON-able dict: meshes as base64 typed arrays, joints, boxes.

Meshes are decimated to a face budget so a whole scan stays a few MB inside a single HTML file.
"""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any

import numpy as np

from ..data.mesh import TriMesh, load_mesh
from ..data.parts import InteractiveObject, InteractiveScene


def _b64(a: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(a).tobytes()).decode("ascii")


def decimate(mesh: TriMesh, max_faces: int) -> TriMesh:
    """Quadric decimation to the face budget; colours taken from the nearest scan vertex.

    fast-simplification (Fast-Quadric-Mesh-Simplification) rather than Open3D's quadric decimation: on a
    1M-face scan 2.2 s instead of 45 s, with a lower colour error (Open3D averages colours over collapses).
    """
    if mesh.n_faces <= max_faces:
        return mesh
    import fast_simplification
    from scipy.spatial import cKDTree

    pts, faces = fast_simplification.simplify(mesh.vertices.astype(np.float32), mesh.faces.astype(np.int64),
                                              target_reduction=1.0 - max_faces / mesh.n_faces)
    _, nearest = cKDTree(mesh.vertices).query(pts, workers=-1)
    return TriMesh(np.asarray(pts, np.float64), np.asarray(faces, np.int64), mesh.colors[nearest])


def mesh_payload(mesh: TriMesh, max_faces: int) -> dict[str, Any]:
    """Positions float32, normals int8, colours uint8, indices uint32 — base64."""
    m = decimate(mesh, max_faces)
    n = np.clip(np.round(m.vertex_normals * 127), -127, 127).astype(np.int8)
    return {
        "positions": _b64(m.vertices.astype(np.float32)),
        "normals": _b64(n),
        "colors": _b64(m.colors.astype(np.uint8)),
        "indices": _b64(m.faces.astype(np.uint32)),
        "n_vertices": int(m.n_vertices),
        "n_faces": int(m.n_faces),
    }


def _object_payload(obj: InteractiveObject, root: Path, max_faces: int) -> dict[str, Any]:
    a = obj.articulation
    out: dict[str, Any] = {
        "id": obj.object_id,
        "label": obj.label,
        "score": obj.score,
        "joint": {
            "type": a.joint_type,
            "axis": list(a.axis),
            "origin": list(a.origin),
            "lower": a.lower,
            "upper": a.upper,
            "limit_source": a.limit_source,
        },
        "obb": {"center": list(obj.obb.center), "axes": [list(x) for x in obj.obb.axes], "extents": list(obj.obb.extents)},
        "front_normal": list(obj.front_normal),
        "cavity_depth": obj.cavity_depth,
        "cavity_depth_source": obj.cavity_depth_source,
        "top_views": obj.top_views,
        "seg_frame_id": obj.seg_frame_id,
        "meshes": {},
    }
    for key, rel in (("part", obj.part_mesh), ("base", obj.base_mesh), ("inner", obj.inner_mesh)):
        if rel:
            p = root / rel
            if p.is_file():
                out["meshes"][key] = mesh_payload(load_mesh(p), max_faces)
    return out


def scene_payload(
    manifest_path: str | Path, max_background_faces: int = 150_000, max_object_faces: int = 20_000
) -> dict[str, Any]:
    """Everything the viewer draws, from a scene manifest (``scene.json`` or its folder)."""
    manifest_path = Path(manifest_path)
    if manifest_path.is_dir():
        manifest_path = manifest_path / "scene.json"
    scene = InteractiveScene.load(manifest_path)
    root = manifest_path.parent
    bg = load_mesh(root / scene.background_mesh)
    return {
        "scene_id": scene.scene_id,
        "background": mesh_payload(bg, max_background_faces),
        "bounds": bg.bounds().tolist(),
        "objects": [_object_payload(o, root, max_object_faces) for o in scene.objects],
        "timings": scene.timings,
        "versions": scene.versions,
    }
