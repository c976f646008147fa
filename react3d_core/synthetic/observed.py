"""Keep only the surfaces a capture of the closed scene observes, as a real scan would.

A reconstructed scan (and so its Articulate3D labels) holds what the sensor saw: the fronts of closed
drawers, not the drawer boxes behind them; the outside of an oven, not its racks. URDF models (e.g.
scene-synthesizer kitchens) carry all that internal geometry, which no perception method can see and
which would dominate a drawer's vertex set (~75 % of it). So for those sources the generated mesh is
culled to the faces hit by rays from a dense camera walk (the capture's own poses included), plus
faces whose three vertices all lie on seen faces (closes sub-pixel sampling gaps).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .procedural import SynthLayout
from .render import RayCaster, scale_K

CULL_SIZE = (480, 360)


def observed_faces(caster: RayCaster, poses: list[np.ndarray], K_full: np.ndarray) -> np.ndarray:
    """Boolean per face: seen from any of ``poses`` (rendered at :data:`CULL_SIZE`), closed over vertices."""
    mesh = caster.mesh
    K = scale_K(K_full, CULL_SIZE[0])
    seen = np.zeros(mesh.n_faces, bool)
    for c2w in poses:
        ids = caster.cast(K, c2w, *CULL_SIZE)["face"]
        seen[ids[ids >= 0]] = True
    vseen = np.zeros(mesh.n_vertices, bool)
    vseen[mesh.faces[seen].ravel()] = True
    return seen | vseen[mesh.faces].all(1)


def keep_faces(layout: SynthLayout, keep: np.ndarray) -> SynthLayout:
    """``layout`` restricted to faces ``keep``; parts/handles/statics left without faces are dropped."""
    mesh, _ = layout.mesh.submesh(np.flatnonzero(keep))
    keys = layout.face_keys[keep]
    present = set(np.unique(keys[keys >= 0]).tolist())
    has = lambda k: k is not None and layout.key_ids.get(k, -1) in present  # noqa: E731
    parts, dropped = [], []
    for p in layout.parts:
        if not has(p.key):
            dropped.append(p.label)
            continue
        parts.append(p if has(p.handle_key) else replace(p, handle_key=None))
    statics = {k: v for k, v in layout.statics.items() if has(k)}
    extra = {**layout.extra, "culled_faces": int((~keep).sum()), "unobserved_parts": dropped}
    mats = layout.face_materials[keep] if layout.face_materials is not None else None
    cols = layout.face_colors[keep] if layout.face_colors is not None else None
    return replace(layout, mesh=mesh, face_keys=keys, parts=parts, statics=statics, extra=extra, face_materials=mats,
                   face_colors=cols)
