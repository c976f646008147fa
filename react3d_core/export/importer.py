"""URDF -> data model: the articulations of an exported (or any single-tree) URDF, in world coordinates."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..data.parts import Articulation
from ..errors import InputError


def _origin(el: ET.Element | None) -> np.ndarray:
    T = np.eye(4)
    if el is None:
        return T
    o = el.find("origin")
    if o is not None:
        T[:3, 3] = [float(x) for x in o.get("xyz", "0 0 0").split()]
        T[:3, :3] = Rotation.from_euler("xyz", [float(x) for x in o.get("rpy", "0 0 0").split()]).as_matrix()
    return T


def import_urdf(path: str | Path) -> dict[str, Articulation]:
    """Joint name -> Articulation (world axis/origin at q = 0, limits) for every revolute/prismatic joint.

    REACT3D joints are named ``<object_id>_joint``; the suffix is stripped. Continuous joints are
    skipped (no limits); world poses follow the kinematic tree from the root link.
    """
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, FileNotFoundError, IsADirectoryError) as exc:
        raise InputError(path, f"cannot read URDF ({exc})") from None
    if root.tag != "robot":
        raise InputError(path, "not a URDF (root element is not <robot>)")
    joints = root.findall("joint")
    by_child = {j.find("child").get("link"): j for j in joints if j.find("child") is not None}  # type: ignore[union-attr]
    cache: dict[str, np.ndarray] = {}

    def link_pose(name: str, depth: int = 0) -> np.ndarray:
        if name in cache:
            return cache[name]
        if depth > 1000:
            raise InputError(path, "kinematic loop in URDF")
        j = by_child.get(name)
        T = np.eye(4) if j is None else link_pose(j.find("parent").get("link"), depth + 1) @ _origin(j)  # type: ignore[union-attr]
        cache[name] = T
        return T

    out: dict[str, Articulation] = {}
    for j in joints:
        kind = j.get("type")
        if kind not in ("revolute", "prismatic"):
            continue
        T = link_pose(j.find("parent").get("link")) @ _origin(j)  # type: ignore[union-attr]
        ax_el = j.find("axis")
        axis = np.array([float(x) for x in (ax_el.get("xyz") if ax_el is not None else "1 0 0").split()])
        lim = j.find("limit")
        if lim is None:
            raise InputError(path, f"joint {j.get('name')} has no <limit>")
        name = j.get("name", "")
        key = name[: -len("_joint")] if name.endswith("_joint") else name
        out[key] = Articulation(
            joint_type=kind, axis=tuple(T[:3, :3] @ axis), origin=tuple(T[:3, 3]),
            lower=float(lim.get("lower", 0)), upper=float(lim.get("upper", 0)), limit_source="urdf",
        )
    return out
