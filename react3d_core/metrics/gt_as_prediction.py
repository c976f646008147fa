"""Write the ground truth itself as a prediction manifest (``scene.json``) — the evaluation's
sanity check: scoring it against its own GT must give perfect numbers."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..data.mesh import load_mesh, save_mesh
from ..data.parts import OBB, InteractiveObject, InteractiveScene, save_vertex_ids
from ..ground_truth.articulate3d import GroundTruth


def _aabb(v: np.ndarray) -> OBB:
    """Axis-aligned box sorted to s1 >= s2 >= s3 (right-handed axes)."""
    lo, hi = (v.min(0), v.max(0)) if len(v) else (np.zeros(3), np.zeros(3))
    ext = hi - lo
    order = np.argsort(-ext, kind="stable")
    R = np.eye(3)[:, order]
    if np.linalg.det(R) < 0:
        R[:, 2] *= -1
    return OBB(center=tuple((lo + hi) / 2), axes=tuple(map(tuple, R.T)), extents=tuple(ext[order]))


def gt_to_scene(gt: GroundTruth, mesh_path: str | Path, out_dir: str | Path) -> Path:
    """Write ``out_dir/scene.json`` with one object per movable GT part: its GT joint and its vertex
    ids (children included, as the evaluation's GT sets), a part mesh cut from the scan. Returns the
    manifest path."""
    out_dir = Path(out_dir)
    mesh_path = Path(mesh_path).resolve()
    mesh = load_mesh(mesh_path)
    sets = gt.movable_vertex_sets(include_children=True)
    objects = []
    for part in gt.movable:
        vids = sets[part.part_id]
        save_vertex_ids(out_dir / "parts" / f"{part.part_id}_vertex_ids.npz", vids)
        faces = part.tri_indices[part.tri_indices < mesh.n_faces]
        sub, _ = mesh.submesh(faces)
        save_mesh(out_dir / "parts" / f"{part.part_id}.ply", sub)
        art = part.articulation
        assert art is not None  # movable parts carry one
        # the true box where the annotation gives it (a part the scan lacks has few or no vertices)
        obb = part.obb if part.obb is not None else _aabb(mesh.vertices[vids])
        objects.append(
            InteractiveObject(
                object_id=f"gt_{part.part_id}", label=part.label, articulation=art, obb=obb,
                front_normal=(1.0, 0.0, 0.0), part_mesh=f"parts/{part.part_id}.ply",
                source_vertex_ids=f"parts/{part.part_id}_vertex_ids.npz",
            )
        )
    scene = InteractiveScene(
        scene_id=gt.scene_id, input_mesh=os.path.relpath(mesh_path, out_dir.resolve()), background_mesh=str(mesh_path),
        objects=objects, versions={"source": "ground-truth"},
    )
    return scene.save(out_dir / "scene.json")
