"""The format-independent export model: links (visuals, collision pieces, inertials) and joints.

Baking and convex decomposition are the expensive steps; they run once here and every writer
(URDF, MJCF, USD) reads the same model. Link frames: background and bases sit at the world origin;
a part link sits at its articulation origin, so q = 0 is the scanned state and the joint needs no
rotation (URDF/MJCF) or only an axis-aligning rotation (USD).
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial import QhullError

from ..config.export import ExportConfig
from ..data.mesh import TriMesh, load_mesh
from ..data.parts import Articulation, InteractiveObject, InteractiveScene
from ..errors import InputError
from ..texture import TexturedMesh, bake_texture
from .clearance import (Obstacle, ObstacleSet, carve_faces, cavity_obstacle, clear_paths, gap, hull_obstacle, keep_clear, keep_side, piece_axes, separate_at_rest,
                        territory_plane)
from .collision import ConvexPiece, cached_pieces, convex_pieces, planar_patches
from .inertia import Inertial, inertial_from_pieces


def safe_name(text: str) -> str:
    """A name valid in URDF, MJCF and as a USD prim (letters, digits, underscore; no leading digit)."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", text)
    return s if s and not s[0].isdigit() else f"_{s}"


RESERVED = ("world", "background", "background_fixed")
"""Link and joint names every export uses for itself."""


def link_names(oid: str) -> dict[str, str]:
    """Names an object's links and joint get in every format: the part is the object (``drawer_03``),
    its joint ``drawer_03_joint``, its carcass ``drawer_03_base`` (fixed by ``drawer_03_base_fixed``)."""
    return {"part": oid, "joint": f"{oid}_joint", "base": f"{oid}_base", "fixed": f"{oid}_base_fixed"}


@dataclass
class Link:
    """One rigid body. ``frame`` is the link origin in world coordinates (rotation is identity)."""

    name: str
    frame: np.ndarray
    visuals: list[TexturedMesh] = field(default_factory=list)
    collisions: list[ConvexPiece] = field(default_factory=list)
    static_mesh: TriMesh | None = None  # exact triangle collision for the static background
    patches: list[ConvexPiece] = field(default_factory=list)  # convex stand-in of static_mesh (MuJoCo)
    inertial: Inertial | None = None
    object_id: str | None = None
    role: str = "background"  # background, base, part
    collide_faces: np.ndarray | None = None  # static_mesh faces that collide (the rest lies in a part's path or a carcass)
    fragments: np.ndarray | None = None  # (k,3,3) colliding pieces of big static faces that were only partly in the way


@dataclass
class Joint:
    name: str
    object_id: str
    parent: str
    child: str
    articulation: Articulation
    damping: float = 0.0  # N s/m or N m s/rad (``joint_damping_for``)


@dataclass
class SceneModel:
    scene_id: str
    links: list[Link]
    joints: list[Joint]
    clearance: dict[str, float] = field(default_factory=dict)  # what separating the colliders did (pieces cut, dropped, conflicts left)

    def link(self, name: str) -> Link:
        return next(link for link in self.links if link.name == name)


def _mesh(root: Path, rel: str | None) -> TriMesh | None:
    if rel is None:
        return None
    p = Path(rel) if Path(rel).is_absolute() else root / rel
    return load_mesh(p)


@dataclass
class _Object:
    """One object while its colliders are being separated."""

    oid: str
    obj: InteractiveObject
    part_meshes: list[TriMesh]
    part: list[ConvexPiece]  # the front's pieces first (``n_front``), then the drawer box's
    base_mesh: TriMesh | None
    base: list[ConvexPiece] | None
    n_front: int = 0
    sweep: list[Obstacle] = field(default_factory=list)

    def pieces(self) -> list[ConvexPiece]:
        return self.part + (self.base or [])


def _box(pieces: list[ConvexPiece]) -> tuple[np.ndarray, np.ndarray]:
    v = np.vstack([p.vertices for p in pieces]) if pieces else np.zeros((1, 3))
    return v.min(0), v.max(0)


def _near(a: list[ConvexPiece], b: list[ConvexPiece], margin: float) -> bool:
    """Whether any piece of ``a`` comes within ``margin`` of one of ``b`` (separating-axis test)."""
    (alo, ahi), (blo, bhi) = _box(a), _box(b)
    if np.any(alo > bhi + margin) or np.any(blo > ahi + margin):
        return False
    for p in a:
        for q in b:
            if np.any(p.vertices.min(0) > q.vertices.max(0) + margin) or np.any(q.vertices.min(0) > p.vertices.max(0) + margin):
                continue
            ob = hull_obstacle(q.vertices, "", "rest")
            if ob is not None and gap(p.vertices, piece_axes(p), ob)[0] < margin:
                return True
    return False


TERRITORY_BOX_MAX_LOSS = 0.9
"""A drawer-box piece that the territory plane would all but remove (a bottom lying a few mm past it)
stays whole; one it crosses (a side wall of a box turned towards its neighbour) is cut."""


TERRITORY_WALL_SHIFT_M = 0.05
"""How far a carcass wall lying wholly on a neighbour's side of the territory plane is moved back to its own
side (m); one further away is left to be dropped."""


def shift_walls(base: list[ConvexPiece], m: np.ndarray, c: float, max_shift: float = TERRITORY_WALL_SHIFT_M) -> list[ConvexPiece]:
    """Carcass walls lying wholly past the plane m . x = c, within ``max_shift`` of it, moved along -m until
    their far face lies on it. Two estimated carcasses stacked or side by side interleave (a cupboard's
    floor a few cm below the drawer box's roof beneath it): cutting each to its side drops both of those
    walls and leaves one open space through both cavities; moved, each keeps its own wall at the
    boundary. Walls the plane crosses are left to the cut, and so are walls deeper along ``m`` than
    ``max_shift``: a plane at an angle to a wall (the bisector of two fronts estimated at an angle) would
    move it by its whole depth along the plane's normal, into the middle of its own cavity."""
    out = []
    for p in base:
        s = p.vertices @ m
        lo = float(s.min())
        if c < lo <= c + max_shift and float(s.max()) - lo <= max_shift:
            shift = float(s.max()) - c
            p = ConvexPiece(p.vertices - shift * m, p.faces, p.source,
                            None if p.box is None else np.concatenate([p.box[:3] - shift * m, p.box[3:]]))
        out.append(p)
    return out


TERRITORY_FRONT_OVERLAP_MAX = 0.1
"""Two fronts of which one reaches past the territory plane by more than this share of its extent across it
overlap (a duplicate detection): the plane is no partition between them, so no carcass wall is moved onto it."""


def fronts_apart(sa: np.ndarray, sb: np.ndarray, c: float, overlap_max: float = TERRITORY_FRONT_OVERLAP_MAX) -> bool:
    """Whether the plane at ``c`` parts two fronts, given their vertices' positions ``sa`` / ``sb`` along its
    normal (A's side below ``c``): each reaches past it by at most ``overlap_max`` of its own extent."""
    over_a = max(0.0, float(sa.max()) - c) / max(float(np.ptp(sa)), 1e-9)
    over_b = max(0.0, c - float(sb.min())) / max(float(np.ptp(sb)), 1e-9)
    return max(over_a, over_b) <= overlap_max


def split_territories(objects: list[_Object], margin: float, box_max_loss: float) -> int:
    """Neighbours whose pieces (front, drawer box, carcass) meet are each cut back to their own side
    of a plane between their fronts (``clearance.territory_plane``), ``margin / 2`` off it: two
    carcasses estimated at an angle, or a drawer box reaching behind its neighbour, then share the
    disputed space instead of both claiming it. A drawer-box piece that would lose more than
    ``box_max_loss`` of itself stays whole (a drawer's bottom a few mm below the plane, where its
    neighbour's front overlaps its own): ``clear_paths`` then cuts whichever of the two loses less. A
    carcass wall wholly on the neighbour's side is moved back onto the plane (``shift_walls``) when the
    plane parts the two fronts (``fronts_apart``). Returns the number of pieces cut."""
    cut = 0
    for i, a in enumerate(objects):
        for b in objects[i + 1 :]:
            if not a.n_front or not b.n_front or not _near(a.pieces(), b.pieces(), margin):
                continue
            fa = np.vstack([p.vertices for p in a.part[: a.n_front]])
            fb = np.vstack([p.vertices for p in b.part[: b.n_front]])
            m, c = territory_plane(fa, np.asarray(a.obj.front_normal), fb, np.asarray(b.obj.front_normal),
                                   axes=np.vstack([np.asarray(a.obj.obb.axes, float), np.asarray(b.obj.obb.axes, float)]))
            apart = fronts_apart(fa @ m, fb @ m, c)
            for o, (mm, cc) in ((a, (m, c - margin / 2)), (b, (-m, -c - margin / 2))):
                front, k1 = keep_side(o.part[: o.n_front], mm, cc)
                inner, k2 = keep_side(o.part[o.n_front :], mm, cc, max_loss=box_max_loss)
                o.part, o.n_front = front + inner, len(front)
                if o.base is not None:
                    o.base, k3 = keep_side(shift_walls(o.base, mm, cc) if apart else o.base, mm, cc)
                    k2 += k3
                cut += k1 + k2
    return cut


def joint_damping_for(inertia: float, config: ExportConfig) -> float:
    """The joint's damping: ``joint_damping``, but never more than ``joint_damping_max_rate`` times what
    the joint moves (its mass or moment about the hinge). A fixed damping on a light part (a small flap
    or a fragment at the minimum mass) stalls any drive scaled to its inertia, and an explicit integrator
    (PyBullet) blows up once ``damping * dt / inertia`` exceeds 2."""
    return float(min(config.joint_damping, config.joint_damping_max_rate * max(inertia, 0.0)))


def obstacle_digest(obstacles: list[Obstacle]) -> str:
    """Content hash of obstacles (cache key of the background carved around them)."""
    h = hashlib.sha256()
    for ob in obstacles:
        h.update(np.ascontiguousarray(ob.vertices, np.float64).tobytes())
        h.update(np.float64(ob.grow).tobytes())
    return h.hexdigest()[:16]


def _body_inertial(pieces: list[ConvexPiece], meshes: list[TriMesh], config: ExportConfig, stats: dict) -> Inertial:
    """The body's inertial from its collision pieces; a body whose pieces were all cut away to keep it
    clear of its neighbours (a carcass lying inside another, a duplicate front) gets it from the convex
    hull of what it shows, so the export is still complete, and is counted in ``bodies_without_colliders``
    (the physics check then reports what it fails to block)."""
    if pieces:
        return inertial_from_pieces(pieces, config.density_kg_m3, config.min_mass_kg)
    stats["bodies_without_colliders"] = stats.get("bodies_without_colliders", 0) + 1  # visible in the manifest
    points = np.vstack([m.vertices for m in meshes if m is not None and len(m.vertices)] or [np.zeros((0, 3))])
    try:
        hull = trimesh.Trimesh(points, process=False).convex_hull
        return inertial_from_pieces([ConvexPiece(np.asarray(hull.vertices), np.asarray(hull.faces), "hull")],
                                    config.density_kg_m3, config.min_mass_kg)
    except (ValueError, IndexError, QhullError):  # flat or empty: a point mass at what it shows
        centre = points.mean(0) if len(points) else np.zeros(3)
        return Inertial(config.min_mass_kg, centre, np.full(3, 1e-6), np.eye(3))


def separate_colliders(objects: list[_Object], config: ExportConfig
                       ) -> tuple[list[Obstacle], list[Obstacle], list[Obstacle], dict[str, float]]:
    """Cut part and carcass pieces back so that no pair overlaps at rest and nothing static stands in a
    part's path (``clearance`` module); returns the obstacles the background is carved around: the
    parts' swept volumes, the carcasses' hulls and their cavities, and counts.

    Neighbours that meet first split the disputed space (``split_territories``). Then: parts over
    carcasses and background (a part is what a robot handles; the carcass is estimated); of two
    part pieces still overlapping at rest the smaller yields; of two carcasses
    the earlier object's. Where a part's path meets another part at rest, the cut that removes less
    volume is made, up to ``part_trim_max_fraction`` of a piece (``clearance.clear_paths``); deeper
    conflicts are left to the joint limits."""
    m = config.collider_clearance_m
    stats = {"parts_cut": 0, "carcass_cut": 0, "pieces_dropped": 0, "part_conflicts_left": 0, "bodies_without_colliders": 0}
    stats["territory_cut"] = split_territories(objects, m, TERRITORY_BOX_MAX_LOSS)
    parts, st = separate_at_rest([o.part for o in objects], m)
    stats["parts_cut"] += st.cut
    stats["pieces_dropped"] += st.dropped
    for o, pieces in zip(objects, parts):
        o.part = pieces
    parts, paths, st = clear_paths([o.part for o in objects], [o.obj.articulation for o in objects], m, config.part_trim_max_fraction)
    stats["parts_cut"] += st.cut
    stats["pieces_dropped"] += st.dropped
    stats["part_conflicts_left"] = st.left
    for o, pieces, path in zip(objects, parts, paths):
        o.part, o.sweep = pieces, path
    sweeps = ObstacleSet([ob for o in objects for ob in o.sweep])
    carcasses: list[Obstacle] = []
    cavities: list[Obstacle] = []
    for o in objects:  # carcasses: out of every path and of earlier carcasses
        if o.base is None:
            continue
        o.base, st = keep_clear(o.base, sweeps, m)
        o.base, st2 = keep_clear(o.base, carcasses, m)
        st.cut += st2.cut
        st.dropped += st2.dropped
        stats["carcass_cut"] += st.cut
        stats["pieces_dropped"] += st.dropped
        hull = hull_obstacle(np.vstack([p.vertices for p in o.base]), o.oid, "carcass") if o.base else None
        if hull is not None:
            carcasses.append(hull)
        cavity = cavity_obstacle(o.base, o.oid)
        if cavity is not None:
            cavities.append(cavity)
    return sweeps.items, carcasses, cavities, stats


def build_scene_model(scene: InteractiveScene, root: str | Path, config: ExportConfig | None = None,
                      cache_dir: str | Path | None = None) -> SceneModel:
    """Bake textures, decompose collisions and compute inertials for every link of ``scene``.

    Colliders are separated (``separate_colliders``) and the background's patches and triangles
    carved around every part's path and every carcass (``collider_clearance_m``).
    ``cache_dir``: convex pieces and background patches are read from / written to it, keyed by mesh
    content and settings (``collision.cached_pieces``); None computes them every time."""
    config = config or ExportConfig()
    root = Path(root)
    bg = _mesh(root, scene.background_mesh)
    assert bg is not None
    thick = config.min_collision_thickness

    def pieces_of(mesh: TriMesh, budget: int) -> list[ConvexPiece]:
        return cached_pieces(cache_dir, "convex", mesh, (budget, thick), lambda: convex_pieces(mesh, budget, thick))

    objects: list[_Object] = []
    seen: set[str] = set(RESERVED)
    for obj in scene.objects:
        oid = safe_name(obj.object_id)
        clash = seen.intersection(link_names(oid).values())
        if clash:
            raise InputError(root / "scene.json", f"object {obj.object_id!r}: its link/joint names {sorted(clash)} collide with another object's or a reserved name")
        seen.update(link_names(oid).values())
        art = obj.articulation
        if not (art.lower <= 0.0 <= art.upper) or art.upper - art.lower <= 0:
            raise InputError(root / "scene.json", f"object {obj.object_id}: joint limits [{art.lower}, {art.upper}] must satisfy lower <= 0 <= upper, lower < upper")
        part = _mesh(root, obj.part_mesh)
        assert part is not None
        moving = [m for m in (part, _mesh(root, obj.inner_mesh)) if m is not None]
        budget = max(1, config.max_convex_hulls // len(moving))
        base = _mesh(root, obj.base_mesh)
        front = pieces_of(part, budget)
        inner = pieces_of(moving[1], budget) if len(moving) > 1 else []
        objects.append(_Object(oid, obj, moving, front + inner, base,
                               pieces_of(base, config.max_convex_hulls) if base is not None else None, n_front=len(front)))
    sweeps, carcasses, cavities, stats = separate_colliders(objects, config)
    margin = config.collider_clearance_m
    # triangles inside a part's path or a carcass stop colliding (the carcass stands for what was scanned
    # there); those merely near stay (the floor under a door's swing, the frame around a front). The slabs
    # fitted to them are cut back to the clearance from every path and cavity; a slab touching a carcass
    # wall from outside stays (two static bodies: no engine collides them).
    keep, fragments = carve_faces(bg.vertices, bg.faces, sweeps + carcasses, 0.0, 4 * config.background_patch_min_m)
    obstacles = sweeps + cavities
    params = (config.background_patch_m, thick, config.background_patch_min_m, config.background_patch_flatness_m, margin,
              config.background_slab_m, obstacle_digest(sweeps + carcasses + cavities))
    patches = cached_pieces(cache_dir, "patches", bg, params, lambda: planar_patches(
        bg, config.background_patch_m, thick, config.background_patch_min_m, config.background_patch_flatness_m, obstacles, margin,
        faces=np.flatnonzero(keep), extra=fragments, slab=config.background_slab_m))
    stats["background_faces_carved"] = int((~keep).sum())
    links = [
        Link(
            "background",
            np.zeros(3),
            visuals=[bake_texture(bg, config)],
            static_mesh=bg,
            patches=patches,
            # static: the inertial only keeps importers from guessing (PyBullet warns, MuJoCo guesses density)
            inertial=Inertial(config.min_mass_kg, bg.vertices.mean(0), np.full(3, 1e-3), np.eye(3)),
            collide_faces=keep,
            fragments=fragments,
        )
    ]
    joints: list[Joint] = []
    for o in objects:
        obj, oid, art = o.obj, o.oid, o.obj.articulation
        names = link_names(oid)
        if o.base_mesh is not None:
            links.append(
                Link(
                    names["base"], np.zeros(3), [bake_texture(o.base_mesh, config)], o.base or [],
                    inertial=_body_inertial(o.base or [], [o.base_mesh], config, stats), object_id=obj.object_id, role="base",
                )
            )
            parent = names["base"]
        else:
            parent = "background"
        inertial = _body_inertial(o.part, o.part_meshes, config, stats)
        links.append(
            Link(
                names["part"], np.asarray(art.origin, float), [bake_texture(m, config) for m in o.part_meshes], o.part,
                inertial=inertial, object_id=obj.object_id, role="part",
            )
        )
        damping = joint_damping_for(inertial.about_joint(art.joint_type, np.asarray(art.axis, float), np.asarray(art.origin, float)), config)
        joints.append(Joint(names["joint"], obj.object_id, parent, names["part"], art, damping))
    return SceneModel(safe_name(scene.scene_id), links, joints, stats)
