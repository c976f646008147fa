"""MJCF writer for MuJoCo: static background, per object a static base body and a moving part body.

MuJoCo convexifies every mesh, so collision pieces are inline convex meshes (one geom each) and the
static background collides through its planar patches (box geoms; a patch cut back near a part is an
inline convex mesh); the textured OBJ visuals (group 1) do not collide. Joint frames match the URDF: the part body sits at the articulation origin.

Collision policy, stated in the file: every collision geom has ``contype="1" conaffinity="1"`` (a
robot with the defaults collides with every part, carcass and the background); a part and its own
carcass are excluded (``<contact><exclude>``): MuJoCo's parent-child filter does not apply to a
carcass welded to the world, while PyBullet (parent exclusion) and PhysX (jointed bodies) skip that
pair, so all engines agree. Static bodies (background, carcasses) never collide with each other in
MuJoCo. The colliders are separated at export (``clearance``), so nothing starts in contact.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from scipy.spatial.transform import Rotation

from ..atomic import write_text
from ..config.export import ExportConfig
from .assets import LinkFiles
from .collision import ConvexPiece
from .model import Link, SceneModel


def _f(x: float) -> str:
    return repr(float(x))


def _v(a: np.ndarray) -> str:
    return " ".join(_f(x) for x in np.asarray(a, float).ravel())


def _inline_mesh(name: str, piece: ConvexPiece, frame: np.ndarray) -> str:
    verts = " ".join("%.9g" % x for x in (piece.vertices - frame).ravel())
    return f'    <mesh name="{name}" vertex="{verts}"/>'


def _assets(link: Link, files: LinkFiles) -> list[str]:
    out = []
    for k, (obj, png) in enumerate(zip(files.visuals, files.mjcf_textures)):
        n = f"{link.name}_visual_{k}"
        out += [
            f'    <mesh name="{n}" file={quoteattr(obj)} inertia="shell"/>',  # visual only: a flat scan has no volume
            f'    <texture name="{n}_tex" type="2d" file={quoteattr(png)}/>',
            f'    <material name="{n}_mat" texture="{n}_tex"/>',
        ]
    for k, piece in enumerate(link.collisions):
        out.append(_inline_mesh(f"{link.name}_col_{k}", piece, link.frame))
    for k, piece in enumerate(link.patches):
        if piece.box is None:
            out.append(_inline_mesh(f"{link.name}_patch_{k}", piece, link.frame))
    return out


def _geoms(link: Link, files: LinkFiles, indent: str) -> list[str]:
    out = []
    for k in range(len(files.visuals)):
        n = f"{link.name}_visual_{k}"
        out.append(f'{indent}<geom name="{n}" type="mesh" mesh="{n}" material="{n}_mat" class="visual"/>')
    for k in range(len(link.collisions)):
        out.append(f'{indent}<geom name="{link.name}_col_{k}" type="mesh" mesh="{link.name}_col_{k}" class="collision"/>')
    for k, piece in enumerate(link.patches):
        n = f"{link.name}_patch_{k}"
        if piece.box is None:
            out.append(f'{indent}<geom name="{n}" type="mesh" mesh="{n}" class="collision"/>')
            continue
        c, R, ext = piece.box_frame()
        x, y, z, w = Rotation.from_matrix(R).as_quat()
        out.append(f'{indent}<geom name="{n}" type="box" pos="{_v(c - link.frame)}" quat="{_v([w, x, y, z])}" size="{_v(ext / 2)}" class="collision"/>')
    return out


def _inertial(link: Link, indent: str) -> list[str]:
    inn = link.inertial
    if inn is None:
        return []
    return [f'{indent}<inertial pos="{_v(inn.com - link.frame)}" quat="{_v(inn.quat_wxyz())}" mass="{_f(inn.mass)}" diaginertia="{_v(inn.moments)}"/>']


def mjcf_text(model: SceneModel, files: dict[str, LinkFiles], config: ExportConfig) -> str:
    """The MJCF document (mesh and texture paths relative to its folder: ``../assets/...`` in an export)."""
    out = [
        f"<mujoco model={quoteattr(model.scene_id)}>",
        '  <compiler angle="radian" meshdir="." texturedir="." autolimits="true" inertiafromgeom="false"/>',
        '  <option timestep="0.002" gravity="0 0 -9.81"/>',
        "  <default>",
        '    <default class="visual"><geom contype="0" conaffinity="0" group="1" density="0"/></default>',
        '    <default class="collision"><geom contype="1" conaffinity="1" group="3" rgba="0.5 0.5 0.5 0.3" density="0"/></default>',
        "  </default>",
        "  <asset>",
    ]
    for link in model.links:
        out += _assets(link, files[link.name])
    out += ["  </asset>", "  <worldbody>", '    <light name="sun" pos="0 0 4" dir="0 0 -1" directional="true"/>']
    bg = model.link("background")
    out += _geoms(bg, files["background"], "    ")
    children: dict[str, list[Link]] = {}
    for j in model.joints:
        children.setdefault(j.parent, []).append(model.link(j.child))
    joint_of = {j.child: j for j in model.joints}

    def body(link: Link, parent_frame: np.ndarray, indent: str) -> list[str]:
        lines = [f'{indent}<body name="{link.name}" pos="{_v(link.frame - parent_frame)}">']
        lines += _inertial(link, indent + "  ")
        j = joint_of.get(link.name)
        if j is not None:
            a = j.articulation
            kind = "hinge" if a.joint_type == "revolute" else "slide"
            lines.append(f'{indent}  <joint name="{j.name}" type="{kind}" pos="0 0 0" axis="{_v(a.axis)}" range="{_f(a.lower)} {_f(a.upper)}" damping="{_f(j.damping)}"/>')
        lines += _geoms(link, files[link.name], indent + "  ")
        for c in children.get(link.name, []):
            lines += body(c, link.frame, indent + "  ")
        lines.append(f"{indent}</body>")
        return lines

    for link in model.links:
        if link.role == "base":
            out += body(link, np.zeros(3), "    ")
    for c in children.get("background", []):
        out += body(c, np.zeros(3), "    ")
    out.append("  </worldbody>")
    excluded = [j for j in model.joints if model.link(j.parent).role == "base"]
    if excluded:
        out.append("  <contact>")
        out += [f'    <exclude name="{j.child}_own_carcass" body1="{j.parent}" body2="{j.child}"/>' for j in excluded]
        out.append("  </contact>")
    out.append("</mujoco>")
    return "\n".join(out) + "\n"


def write_mjcf(model: SceneModel, files: dict[str, LinkFiles], folder: Path, config: ExportConfig) -> Path:
    return write_text(Path(folder) / "scene.xml", mjcf_text(model, files, config))
