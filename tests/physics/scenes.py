"""Hand-made scenes for the physics check (exported once per session by conftest.py with the real exporters).

Geometry (metres, z up; the room is at y < 0.5, the cabinets stand against a wall at y = 1):
- background: a floor slab (top at z = 0) and a wall slab (front at y = 1);
- door cabinet x in [-1, -0.5], z in [0.02, 0.62], open at y = 0.5, walls 2 cm; the door a 2 cm plate
  at y in [0.47, 0.49], hinge at x = -0.99 on the front's mid-surface, axis -z (q > 0 swings it into
  the room), limits [0, pi/2];
- drawer cabinet x in [0, 0.6], z in [0.02, 0.32]; the drawer front y in [0.47, 0.49] with an open-top
  inner box x in [0.04, 0.56], y in [0.49, 0.95], z in [0.06, 0.26] (1 cm walls), axis -y, limits [0, 0.4].

``overlapping``: the clean export with two background colliders added to the written URDF and MJCF, a
block through the closed door (x in [-0.9, -0.8], y in [0.40, 0.55], z in [0.25, 0.45]) and one in the
middle of the door's cavity (x in [-0.8, -0.7], y in [0.65, 0.8], z in [0.25, 0.4]): scanned geometry
left in the background, as it stays when the exporter's carving misses (the exporter itself carves such
blocks out of a scanned background, so they are added after it). The drawer is untouched (its joint must
still pass).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from react3d_core.config.export import ExportConfig
from react3d_core.data import OBB, Articulation, InteractiveObject, InteractiveScene, TriMesh, save_mesh

DOOR = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(-0.99, 0.48, 0.32), lower=0.0, upper=np.pi / 2, limit_source="test")
DRAWER = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0.3, 0.48, 0.17), lower=0.0, upper=0.4, limit_source="test")
INNER_LO, INNER_HI = (0.04, 0.49, 0.06), (0.56, 0.95, 0.26)
FAST = ExportConfig(texel_per_m=50, ros_launch=False)


def box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> trimesh.Trimesh:
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(extents=hi_ - lo_).apply_translation((lo_ + hi_) / 2)


def open_box(lo: tuple[float, float, float], hi: tuple[float, float, float], t: float, open_side: str) -> list[trimesh.Trimesh]:
    """Five walls of thickness ``t`` inside [lo, hi]; ``open_side`` is '-y' (front) or '+z' (top)."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    walls = {
        "-x": box((x0, y0, z0), (x0 + t, y1, z1)),
        "+x": box((x1 - t, y0, z0), (x1, y1, z1)),
        "-z": box((x0 + t, y0, z0), (x1 - t, y1, z0 + t)),
        "+z": box((x0 + t, y0, z1 - t), (x1 - t, y1, z1)),
        "+y": box((x0 + t, y1 - t, z0 + t), (x1 - t, y1, z1 - t)),
        "-y": box((x0 + t, y0, z0 + t), (x1 - t, y0 + t, z1 - t)),
    }
    walls.pop(open_side)
    if open_side == "+z":
        walls["+y"] = box((x0 + t, y1 - t, z0 + t), (x1 - t, y1, z1))
        walls["-y"] = box((x0 + t, y0, z0 + t), (x1 - t, y0 + t, z1))
    return list(walls.values())


def mesh(parts: list[trimesh.Trimesh], grey: int = 160, max_edge: float | None = None) -> TriMesh:
    """One vertex-coloured mesh; ``max_edge``: subdivide (a scan's background has small triangles, and the
    exporter cuts it into patches by the cell of each triangle's centre)."""
    m = trimesh.util.concatenate(parts)
    v, f = (m.vertices, m.faces) if max_edge is None else trimesh.remesh.subdivide_to_size(m.vertices, m.faces, max_edge)
    return TriMesh(v, f, np.full((len(v), 3), grey, np.uint8))


LEFT_IN_BACKGROUND = [((-0.9, 0.40, 0.25), (-0.8, 0.55, 0.45)), ((-0.8, 0.65, 0.25), (-0.7, 0.8, 0.4))]
"""(lo, hi) of the blocks ``overlapping`` leaves in the background: through the closed door, in its cavity."""


BLOCKER = Articulation(joint_type="prismatic", axis=(0, 0, 1), origin=(0.3, 0.215, 0.2), lower=0.0, upper=0.1, limit_source="test")
BLOCKER_LO, BLOCKER_HI = (0.1, 0.2, 0.1), (0.5, 0.23, 0.3)
"""``blocker=True``: a plate on a vertical slide standing in the room 24 cm in front of the drawer's front,
so that the drawer (0.4 m of travel) runs into it after about 0.24 m (a near neighbour held at 0)."""


def build_scene(out: Path, door_front: bool = True, blocker: bool = False) -> Path:
    """Write the scene's manifest and meshes under ``out``; returns the manifest path.

    ``door_front=False`` leaves only the door's handle in its part mesh (the front plate is missing: a
    probe thrown at the front must get through); ``blocker=True`` adds ``BLOCKER``."""
    meshes = out / "meshes"
    bg = [box((-2.0, -2.0, -0.05), (2.0, 1.0, 0.0)), box((-2.0, 1.0, -0.05), (2.0, 1.05, 2.0))]
    save_mesh(meshes / "background.ply", mesh(bg, 120, max_edge=0.1))
    handle = box((-0.6, 0.44, 0.30), (-0.56, 0.47, 0.40))
    door = [box((-0.99, 0.47, 0.03), (-0.51, 0.49, 0.61)), handle] if door_front else [handle]
    save_mesh(meshes / "door" / "part.ply", mesh(door, 200))
    save_mesh(meshes / "door" / "base.ply", mesh(open_box((-1.0, 0.5, 0.02), (-0.5, 1.0, 0.62), 0.02, "-y")))
    save_mesh(meshes / "drawer" / "part.ply", mesh([box((0.01, 0.47, 0.03), (0.59, 0.49, 0.31))], 200))
    save_mesh(meshes / "drawer" / "inner.ply", mesh(open_box(INNER_LO, INNER_HI, 0.01, "+z"), 180))
    save_mesh(meshes / "drawer" / "base.ply", mesh(open_box((0.0, 0.5, 0.02), (0.6, 1.0, 0.32), 0.02, "-y")))
    ex = ((1, 0, 0), (0, 0, 1), (0, 1, 0))
    objects = [
        InteractiveObject(
            object_id="door", label="door", articulation=DOOR,
            obb=OBB(center=(-0.75, 0.48, 0.32), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.58, 0.48, 0.02)),
            front_normal=(0, 1, 0), part_mesh="meshes/door/part.ply", base_mesh="meshes/door/base.ply", cavity_depth=0.48,
        ),
        InteractiveObject(
            object_id="drawer", label="drawer", articulation=DRAWER,
            obb=OBB(center=(0.3, 0.48, 0.17), axes=ex, extents=(0.58, 0.28, 0.02)),
            front_normal=(0, 1, 0), part_mesh="meshes/drawer/part.ply", base_mesh="meshes/drawer/base.ply",
            inner_mesh="meshes/drawer/inner.ply", cavity_depth=0.48,
        ),
    ]
    if blocker:
        save_mesh(meshes / "blocker" / "part.ply", mesh([box(BLOCKER_LO, BLOCKER_HI)], 220))
        objects.append(InteractiveObject(
            object_id="blocker", label="drawer", articulation=BLOCKER,
            obb=OBB(center=(0.3, 0.215, 0.2), axes=ex, extents=(0.4, 0.2, 0.03)),
            front_normal=(0, 1, 0), part_mesh="meshes/blocker/part.ply"))
    scene = InteractiveScene(scene_id="physics_room", input_mesh="meshes/background.ply",
                             background_mesh="meshes/background.ply", objects=objects)
    return scene.save(out / "scene.json")


def export(out: Path, overlapping: bool = False, **kw: bool) -> Path:
    from react3d_core.export import export_scene

    build_scene(out, **kw)
    export_scene(out / "scene.json", config=FAST)
    if overlapping:
        leave_in_background(out, LEFT_IN_BACKGROUND)
    return out


def leave_in_background(out: Path, boxes: list[tuple[tuple[float, float, float], tuple[float, float, float]]]) -> None:
    """Add axis-aligned boxes (world lo, hi) to the background's colliders in the written URDF and MJCF
    (the background's frame is the world's in both)."""
    urdf, mjcf = out / "export" / "urdf" / "scene.urdf", out / "export" / "mjcf" / "scene.xml"
    u, m = urdf.read_text(), mjcf.read_text()
    start = u.index('<link name="background">')
    end = u.index("</link>", start)
    col, geoms = "", ""
    for k, (lo, hi) in enumerate(boxes):
        c, e = (np.add(lo, hi) / 2).tolist(), np.subtract(hi, lo).tolist()
        col += (f'    <collision name="left_{k}"><origin xyz="{c[0]} {c[1]} {c[2]}" rpy="0 0 0"/>'
                f'<geometry><box size="{e[0]} {e[1]} {e[2]}"/></geometry></collision>\n')
        geoms += f'    <geom name="left_{k}" type="box" pos="{c[0]} {c[1]} {c[2]}" size="{e[0] / 2} {e[1] / 2} {e[2] / 2}" class="collision"/>\n'
    urdf.write_text(u[:end] + col.lstrip() + "  " + u[end:])
    anchor = m.index("<worldbody>")
    anchor = m.index("\n", m.index('<geom name="background_', anchor)) + 1
    mjcf.write_text(m[:anchor] + geoms + m[anchor:])
