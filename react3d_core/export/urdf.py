"""URDF writer: one scene file with a fixed world/background, per object a fixed base and one joint.

Joint frames: the joint origin is the articulation origin with no rotation, the axis is the world
axis (= the joint-frame axis), and the part link's meshes are stored relative to that origin, so
q = 0 is the scanned state and the motion equals ``Articulation.move``. The static background
collides through convex planar patches (``<box>`` primitives; a patch cut back near a part is a
convex OBJ): PyBullet ignores ``concave="yes"`` on a non-root link and
MuJoCo convexifies every mesh, so one triangle-mesh collider became the room's solid hull (measured:
a dropped ball was expelled through the floor). The ``<mujoco>`` block keeps
visuals and the static bodies when MuJoCo imports this URDF.

Collision policy: URDF has no element for it, so it is what the engines do, written into the file
as a comment. PyBullet collides links of one body only with ``URDF_USE_SELF_COLLISION`` (add
``URDF_USE_SELF_COLLISION_EXCLUDE_PARENT`` so a part and its carcass do not collide); SAPIEN/PhysX
collide all links of an articulation except a joint's two; MuJoCo's URDF import collides a part with
its carcass (add an ``<exclude>`` or use the MJCF). The colliders are separated at export
(``clearance``), so self-collision on starts without contacts.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..atomic import write_text
from ..config.export import ExportConfig
from .assets import LinkFiles
from .collision import ConvexPiece
from .inertia import rpy_of
from .model import Link, SceneModel


def _f(x: float) -> str:
    return repr(float(x))


def _v(a: np.ndarray) -> str:
    return " ".join(_f(x) for x in np.asarray(a, float).ravel())


def _inertial(link: Link) -> list[str]:
    inn = link.inertial
    if inn is None:
        return []
    I = np.diag(inn.moments)
    return [
        "    <inertial>",
        f'      <origin xyz="{_v(inn.com - link.frame)}" rpy="{_v(inn.rpy())}"/>',
        f'      <mass value="{_f(inn.mass)}"/>',
        f'      <inertia ixx="{_f(I[0, 0])}" ixy="0" ixz="0" iyy="{_f(I[1, 1])}" iyz="0" izz="{_f(I[2, 2])}"/>',
        "    </inertial>",
    ]


def _box(piece: ConvexPiece, frame: np.ndarray) -> tuple[str, str, str]:
    """(xyz, rpy, geometry) of a box piece: URDF's rpy is fixed-axis roll, pitch, yaw (R = Rz Ry Rx)."""
    c, R, ext = piece.box_frame()
    return _v(c - frame), _v(rpy_of(R)), f'<box size="{_v(ext)}"/>'


POLICY = (
    "<!-- Collision policy: colliders are separated at rest and around every part's path. Load with self-collision on and "
    "parent exclusion (PyBullet: URDF_USE_SELF_COLLISION | URDF_USE_SELF_COLLISION_EXCLUDE_PARENT; SAPIEN/PhysX do this by "
    "default) so a part never collides with its own carcass (its parent link) and collides with everything else. Colliders are "
    "a few mm apart: in PyBullet set contactBreakingThreshold below that gap (setPhysicsEngineParameter, e.g. 0.002), or "
    "contact points kept from 2 cm away jam a part sliding past its neighbour. -->"
)


def urdf_text(model: SceneModel, files: dict[str, LinkFiles], config: ExportConfig, prefix: str = "") -> str:
    """The URDF document; mesh paths are ``prefix + relative path`` (``package://pkg/`` for ROS)."""
    out = ['<?xml version="1.0"?>', POLICY, f"<robot name={quoteattr(model.scene_id)}>"]
    out += ["  <mujoco>", '    <compiler strippath="false" discardvisual="false" fusestatic="false" balanceinertia="true"/>', "  </mujoco>"]
    out += ['  <link name="world"/>']
    for link in model.links:
        f = files[link.name]
        out.append(f'  <link name="{link.name}">')
        out += _inertial(link)
        for k, vis in enumerate(f.visuals):
            out += [
                f'    <visual name="{link.name}_visual_{k}">',
                '      <origin xyz="0 0 0" rpy="0 0 0"/>',
                f'      <geometry><mesh filename="{prefix}{vis}"/></geometry>',
                "    </visual>",
            ]
        meshes = iter(f.patches)
        cols = [_box(p, link.frame) if p.box is not None else (_v(p.centre - link.frame), "0 0 0", f'<mesh filename="{prefix}{next(meshes)}"/>')
                for p in link.patches]
        cols += [(_v(p.centre - link.frame), "0 0 0", f'<mesh filename="{prefix}{col}"/>') for p, col in zip(link.collisions, f.collisions, strict=True)]
        for k, (xyz, rpy, geometry) in enumerate(cols):
            out += [
                f'    <collision name="{link.name}_collision_{k}">',
                f'      <origin xyz="{xyz}" rpy="{rpy}"/>',
                f"      <geometry>{geometry}</geometry>",
                "    </collision>",
            ]
        out.append("  </link>")
    out += [
        '  <joint name="background_fixed" type="fixed">',
        '    <parent link="world"/><child link="background"/><origin xyz="0 0 0" rpy="0 0 0"/>',
        "  </joint>",
    ]
    for link in model.links:
        if link.role == "base":
            out += [
                f'  <joint name="{link.name}_fixed" type="fixed">',
                f'    <parent link="background"/><child link="{link.name}"/><origin xyz="{_v(link.frame)}" rpy="0 0 0"/>',
                "  </joint>",
            ]
    for j in model.joints:
        a = j.articulation
        parent = model.link(j.parent)
        child = model.link(j.child)
        kind = "revolute" if a.joint_type == "revolute" else "prismatic"
        out += [
            f'  <joint name="{j.name}" type="{kind}">',
            f'    <parent link="{j.parent}"/><child link="{j.child}"/>',
            f'    <origin xyz="{_v(child.frame - parent.frame)}" rpy="0 0 0"/>',
            f'    <axis xyz="{_v(a.axis)}"/>',
            f'    <limit lower="{_f(a.lower)}" upper="{_f(a.upper)}" effort="{_f(config.joint_effort)}" velocity="{_f(config.joint_velocity)}"/>',
            f'    <dynamics damping="{_f(j.damping)}" friction="0"/>',
            "  </joint>",
        ]
    out.append("</robot>")
    return "\n".join(out) + "\n"


def write_urdf(model: SceneModel, files: dict[str, LinkFiles], folder: Path, config: ExportConfig, prefix: str = "") -> Path:
    return write_text(Path(folder) / "scene.urdf", urdf_text(model, files, config, prefix))


def write_ros_package(model: SceneModel, files: dict[str, LinkFiles], pkg_dir: Path, config: ExportConfig) -> Path:
    """Minimal ROS 2 description package: package.xml, CMakeLists.txt, urdf/scene.urdf with package:// paths.

    ``pkg_dir`` must already hold ``meshes/`` (written by ``write_link_assets``)."""
    name = pkg_dir.name
    write_text(
        pkg_dir / "package.xml",
        f"""<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>Interactive scene {model.scene_id} exported by REACT3D</description>
  <maintainer email="react3d@example.com">REACT3D</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <exec_depend>robot_state_publisher</exec_depend>
  <exec_depend>joint_state_publisher_gui</exec_depend>
  <exec_depend>rviz2</exec_depend>
  <export><build_type>ament_cmake</build_type></export>
</package>
""",
    )
    write_text(
        pkg_dir / "CMakeLists.txt",
        f"cmake_minimum_required(VERSION 3.8)\nproject({name})\nfind_package(ament_cmake REQUIRED)\n"
        "install(DIRECTORY urdf meshes DESTINATION share/${PROJECT_NAME})\nament_package()\n",
    )
    return write_text(pkg_dir / "urdf" / "scene.urdf", urdf_text(model, files, config, prefix=f"package://{name}/"))
