"""Any articulated URDF (PartNet-Mobility objects, scene-synthesizer kitchens, robot kitchens) as a scan.

All joints are posed closed (q clamped to 0 within limits), every link's visual geometry is merged into
one vertex-coloured mesh subdivided to scan-like triangle sizes, and every movable joint becomes a GT
part made of the geometry of the links it moves (a link named ``*handle*`` becomes its ``.handle``
child). Joint axes are flipped where needed so that q in [0, upper] opens. The object stands in a room
shell, and the camera sweeps every group of fronts that face the same way.

Cavity depths are not known for arbitrary URDFs: ``interior_depth`` is None. Internal geometry that a
capture of the closed scene never sees (drawer boxes, appliance insides) is culled (``observed.py``).

``up`` names the asset's up axis (many exporters write Y-up) and ``scale`` its unit (0.01 for
centimetres): the asset is rotated so that axis becomes the scene's +z and scaled, joints with it.
Where the joints say otherwise (drawers that would slide vertically, hinges lying along another axis)
a warning goes to the log and to ``synth_meta.json`` (``up_warnings``): a wrong up axis used to give a
cabinet lying on its side without a word.
"""

from __future__ import annotations

import logging
import re
import zlib
from pathlib import Path

import numpy as np

from ..data.parts import Articulation
from ..errors import InputError
from ..raster import Rasterizer
from .builder import MeshBuilder, bisect_to_size
from .furniture import PartSpec, WallFrame
from .materials import GLOSSY, MATTE, METAL, WOOD
from .procedural import SynthLayout, ViewRun, shell

SKIP = re.compile(r"basket|rack", re.I)  # internal sliding parts (dishwasher baskets) are not fronts
MARGIN = 2.2  # free floor around the object(s), metres
log = logging.getLogger(__name__)

# proper rotations taking the named asset axis to +z (Y-up -> Z-up: +90 deg about x)
UP_AXES: dict[str, np.ndarray] = {
    "z": np.eye(3),
    "-z": np.diag([1.0, -1.0, -1.0]),
    "y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
    "-y": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),
    "x": np.array([[0.0, 0, -1], [0, 1, 0], [1, 0, 0]]),
    "-x": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),
}
#: a joint axis within ~25 deg of a coordinate axis counts as lying along it
ALONG = 0.9


def up_axis_votes(joint_types: list[str], axes: np.ndarray) -> np.ndarray:
    """Evidence for x, y, z (scene frame) being up: a hinge along an axis counts +1 (doors turn about
    vertical hinges; oven doors and flaps do not, hence a small weight), a slide along it -2 (drawers and
    sliding doors move horizontally)."""
    votes = np.zeros(3)
    for jt, ax in zip(joint_types, np.asarray(axes, float).reshape(-1, 3)):
        along = np.abs(ax) / max(np.linalg.norm(ax), 1e-12) > ALONG
        votes += np.where(along, 1.0 if jt == "revolute" else -2.0, 0.0)
    return votes


def up_warnings(joint_types: list[str], axes: np.ndarray, extents: np.ndarray, up: str) -> list[str]:
    """Why the asset's up axis looks wrong after rotating ``up`` to +z (empty if it looks right)."""
    names = "xyz"
    axes = np.asarray(axes, float).reshape(-1, 3)
    out = []
    slides = [ax for jt, ax in zip(joint_types, axes) if jt == "prismatic"]
    vertical = sum(abs(ax[2]) / max(np.linalg.norm(ax), 1e-12) > ALONG for ax in slides)
    if slides and 2 * vertical > len(slides):
        out.append(f"{vertical} of {len(slides)} prismatic joints would slide vertically")
    votes = up_axis_votes(joint_types, axes)
    best = int(np.argmax(votes))
    if best != 2 and votes[best] >= votes[2] + 2:
        out.append(f"the joints point to scene {names[best]} as up (score {votes[best]:g} vs {votes[2]:g} for z; "
                   f"bounding box {' x '.join(f'{e:.2f}' for e in extents)} m)")
    if out:
        out.append(f"--up {up} may be wrong: try another --up (x, y, z, -x, -y, -z)")
    return out


def _subdivide(v: np.ndarray, f: np.ndarray, edge: float) -> tuple[np.ndarray, np.ndarray]:
    if len(f) == 0:
        return v, f
    return bisect_to_size(v, f, edge)


def _color(geom, name: str) -> tuple[int, int, int]:  # noqa: ANN001
    try:
        c = np.asarray(geom.visual.to_color().vertex_colors)[:, :3]
        if len(c) and np.ptp(c) + c.mean() > 0:
            return tuple(int(x) for x in c.mean(0))
    except Exception:  # noqa: BLE001 - visuals vary a lot between URDFs; fall back to a name colour
        pass
    h = zlib.crc32(name.encode()) % 997  # not hash(): str hashes change per process
    return (120 + h % 100, 110 + (h // 7) % 100, 100 + (h // 49) % 100)


def build_from_urdf(path: Path, seed: int = 0, edge: float = 0.03, kind: str = "urdf", up: str = "z",
                    scale: float = 1.0) -> SynthLayout:
    """Merge a closed URDF into a :class:`SynthLayout` with one GT part per movable joint; ``up`` (a key
    of :data:`UP_AXES`) is turned to +z and lengths are multiplied by ``scale``."""
    import yourdfpy

    if up not in UP_AXES:
        raise ValueError(f"unknown up axis {up!r}; choose from {', '.join(UP_AXES)}")
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive number, got {scale}")
    Rup = UP_AXES[up] * scale  # rotation then scale, for points and joint origins (axes: rotation only)
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "URDF file not found")
    try:
        u = yourdfpy.URDF.load(str(path), load_meshes=True, build_collision_scene_graph=False)
    except Exception as exc:  # noqa: BLE001 - yourdfpy raises many types on bad XML/meshes
        raise InputError(path, f"cannot load URDF ({exc})") from None
    joints = {j.name: j for j in u.robot.joints}
    movable = [j for j in u.robot.joints if j.type in ("revolute", "prismatic", "continuous")]
    if not movable:
        raise InputError(path, "URDF has no revolute/prismatic joints")
    q0 = []
    for name in u.actuated_joint_names:
        j = joints[name]
        lo = j.limit.lower if j.limit is not None and j.limit.lower is not None else -np.inf
        hi = j.limit.upper if j.limit is not None and j.limit.upper is not None else np.inf
        q0.append(float(np.clip(0.0, lo, hi)))
    u.update_cfg(np.array(q0))
    q0_of = dict(zip(u.actuated_joint_names, q0))
    parent_joint = {j.child: j for j in u.robot.joints}

    def owner(link: str) -> str | None:
        """The movable joint whose motion moves ``link`` (nearest movable ancestor)."""
        while link in parent_joint:
            j = parent_joint[link]
            if j.type != "fixed":
                return None if SKIP.search(j.name) else j.name
            link = j.parent
        return None

    sc, g = u.scene, u.scene.graph
    links = set(u.link_map)
    pieces: dict[str, list[tuple[np.ndarray, np.ndarray, tuple[int, int, int]]]] = {}
    for node in g.nodes_geometry:
        T, gname = g[node]
        link = node
        while link not in links and link in g.transforms.parents:
            link = g.transforms.parents[link]
        geom = sc.geometry[gname]
        v = (np.asarray(geom.vertices, float) @ T[:3, :3].T + T[:3, 3]) @ Rup.T
        jn = owner(link)
        key = (jn + (".handle" if "handle" in node.lower() or "handle" in link.lower() else "")) if jn else f"static:{link}"
        pieces.setdefault(key, []).append((v, np.asarray(geom.faces, np.int64), _color(geom, node)))
    allv = np.concatenate([p[0] for ps in pieces.values() for p in ps])
    lo, hi = allv.min(0), allv.max(0)
    offset = np.array([MARGIN - lo[0], MARGIN - lo[1], -lo[2]])
    W, L = hi[0] - lo[0] + 2 * MARGIN, hi[1] - lo[1] + 2 * MARGIN
    H = max(2.5, hi[2] - lo[2] + 0.4)
    rng = np.random.default_rng(seed)
    m = MeshBuilder(edge=edge, seed=seed)
    shell(m, rng, W, L, H, None)
    statics: dict[str, str] = {}
    front_mat = (GLOSSY, WOOD, MATTE)[seed % 3]  # one front finish per scene (photo renderer only)
    for key in sorted(pieces):
        mat = METAL if key.endswith(".handle") else MATTE if key.startswith("static:") else front_mat
        for v, f, col in pieces[key]:
            # hidden carcass boards need fewer triangles than the fronts the pipeline segments
            vv, ff = _subdivide(v + offset, f, edge * (2.5 if key.startswith("static:") else 1.5))
            m.add(vv, ff, col, key, material=mat)
        if key.startswith("static:"):
            statics[key] = key.split(":", 1)[1]
    parts: list[PartSpec] = []
    for j in movable:
        if SKIP.search(j.name) or j.name not in pieces:
            continue
        Tc = g.get(j.child)[0]
        axis = UP_AXES[up] @ Tc[:3, :3] @ np.asarray(j.axis, float)
        origin = Rup @ Tc[:3, 3] + offset
        q = q0_of.get(j.name, 0.0)
        lo_q = (j.limit.lower if j.limit is not None and j.limit.lower is not None else -np.pi) - q
        hi_q = (j.limit.upper if j.limit is not None and j.limit.upper is not None else np.pi) - q
        if j.type == "prismatic":  # travel is a length: it scales with the asset
            lo_q, hi_q = lo_q * scale, hi_q * scale
        if hi_q <= 1e-9:  # opens towards negative q: flip the axis so q in [0, upper] opens
            axis, lo_q, hi_q = -axis, -hi_q, -lo_q
        jt = "prismatic" if j.type == "prismatic" else "revolute"
        kind_ = "drawer" if jt == "prismatic" else ("door" if abs(axis[2]) > 0.7 else "flap")
        art = Articulation(joint_type=jt, axis=axis, origin=origin, lower=0.0, upper=float(hi_q), limit_source="gt")
        parent_link = j.parent
        pkey = f"static:{parent_link}" if f"static:{parent_link}" in pieces else None
        label = f"{parent_link}.{kind_}_{len(parts) + 1}"
        parts.append(PartSpec(j.name, label, kind_, art, pkey, j.name + ".handle" if j.name + ".handle" in pieces else None, None))
    mesh, keys, key_ids = m.build()
    warn = up_warnings([p.articulation.joint_type for p in parts], np.array([p.articulation.axis for p in parts]),
                       hi - lo, up)
    for w in warn:
        log.warning("%s: %s", path.name, w)
    runs = _runs(mesh, keys, key_ids, parts, W, L)
    return SynthLayout(mesh, keys, key_ids, parts, statics, runs, (W, L, H), kind,
                       extra={"urdf": str(path.name), "offset": offset.tolist(), "skipped_joints": [j.name for j in movable if SKIP.search(j.name)],
                              "up": up, "scale": scale, "up_warnings": warn},
                       observed_only=True, face_materials=m.materials(), face_colors=m.base_colors())


def _runs(mesh, keys, key_ids, parts: list[PartSpec], W: float, L: float) -> list[ViewRun]:  # noqa: ANN001
    """One camera run per group of fronts that open towards the same side (nearest of 4 directions)."""
    raster = Rasterizer(mesh)  # built once for every run's free-depth probe
    groups: dict[int, list[np.ndarray]] = {}
    for p in parts:
        sel = keys == key_ids[p.key]
        v = mesh.vertices[np.unique(mesh.faces[sel].ravel())]
        c = v.mean(0)
        a = p.articulation
        out = a.move(c[None], 0.2 * a.upper)[0] - c
        out[2] = 0.0
        if np.linalg.norm(out) < 1e-6:
            continue
        k = int(np.round(np.arctan2(out[1], out[0]) / (np.pi / 2))) % 4  # 0:+x 1:+y 2:-x 3:-y
        groups.setdefault(k, []).append(v)
    runs = []
    for k, vs in sorted(groups.items()):
        out = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]][k], float)
        inward = -out
        theta = float(np.arctan2(-inward[0], inward[1]))  # R(theta) @ (0, 1) = inward
        fr = WallFrame(np.zeros(3), theta)
        R = fr.T[:3, :3]
        loc = np.concatenate(vs) @ R  # world -> wall frame (origin at 0)
        y_front = loc[:, 1].min()
        fr = WallFrame(R @ np.array([0.0, y_front, 0.0]), theta)
        loc = loc - np.array([0.0, y_front, 0.0])
        c = np.concatenate(vs).mean(0)
        free = min({0: W - c[0], 1: L - c[1], 2: c[0], 3: c[1]}[k],
                   _free_depth(raster, fr, float(loc[:, 0].min()), float(loc[:, 0].max()), out))
        runs.append(ViewRun(fr, float(loc[:, 0].min()), float(loc[:, 0].max()), float(loc[:, 2].min()),
                            float(loc[:, 2].max()), 0.0, float(free)))
    return runs


def _free_depth(raster: Rasterizer, fr: WallFrame, x0: float, x1: float, out: np.ndarray) -> float:
    """Free distance in front of a run at camera heights (``raster``: the layout's ray caster):
    furniture facing it across an aisle (an island facing a counter) must not hide the fronts from
    the cameras meant to film them."""
    T = fr.T
    xs = np.linspace(x0, x1, 7)
    starts = np.array([T[:3, :3] @ np.array([x, -0.05, z]) + T[:3, 3] for x in xs for z in (1.0, 1.3, 1.6)])
    d = np.array([out[0], out[1], 0.0])
    t = raster.cast_rays(starts, np.broadcast_to(d, starts.shape)).t
    t = t[np.isfinite(t)]
    return float(np.median(t)) + 0.05 if len(t) else np.inf
