"""The format-independent export model: links (visuals, collision pieces, inertials) and joints.

Baking and convex decomposition are the expensive steps; they run once here and every writer
(URDF, MJCF, USD) reads the same model. Link frames: background and bases sit at the world origin;
a part link sits at its articulation origin, so q = 0 is the scanned state and the joint needs no
rotation (URDF/MJCF) or only an axis-aligning rotation (USD).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config.export import ExportConfig
from ..data.mesh import TriMesh, load_mesh
from ..data.parts import Articulation, InteractiveScene
from ..errors import InputError
from ..texture import TexturedMesh, bake_texture
from .collision import ConvexPiece, cached_pieces, convex_pieces, planar_patches
from .inertia import Inertial, inertial_from_pieces


def safe_name(text: str) -> str:
    """A name valid in URDF, MJCF and as a USD prim (letters, digits, underscore; no leading digit)."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", text)
    return s if s and not s[0].isdigit() else f"_{s}"


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


@dataclass
class Joint:
    name: str
    object_id: str
    parent: str
    child: str
    articulation: Articulation


@dataclass
class SceneModel:
    scene_id: str
    links: list[Link]
    joints: list[Joint]

    def link(self, name: str) -> Link:
        return next(link for link in self.links if link.name == name)


def _mesh(root: Path, rel: str | None) -> TriMesh | None:
    if rel is None:
        return None
    p = Path(rel) if Path(rel).is_absolute() else root / rel
    return load_mesh(p)


def build_scene_model(scene: InteractiveScene, root: str | Path, config: ExportConfig | None = None,
                      cache_dir: str | Path | None = None) -> SceneModel:
    """Bake textures, decompose collisions and compute inertials for every link of ``scene``.

    ``cache_dir``: convex pieces and background patches are read from / written to it, keyed by mesh
    content and settings (``collision.cached_pieces``); None computes them every time."""
    config = config or ExportConfig()
    root = Path(root)
    bg = _mesh(root, scene.background_mesh)
    assert bg is not None
    thick = config.min_collision_thickness

    def pieces_of(mesh: TriMesh, budget: int) -> list[ConvexPiece]:
        return cached_pieces(cache_dir, "convex", mesh, (budget, thick), lambda: convex_pieces(mesh, budget, thick))

    patches = cached_pieces(cache_dir, "patches", bg, (config.background_patch_m, thick),
                            lambda: planar_patches(bg, config.background_patch_m, thick))
    links = [
        Link(
            "background",
            np.zeros(3),
            visuals=[bake_texture(bg, config)],
            static_mesh=bg,
            patches=patches,
            # static: the inertial only keeps importers from guessing (PyBullet warns, MuJoCo guesses density)
            inertial=Inertial(config.min_mass_kg, bg.vertices.mean(0), np.full(3, 1e-3), np.eye(3)),
        )
    ]
    joints: list[Joint] = []
    seen: set[str] = set()
    for obj in scene.objects:
        oid = safe_name(obj.object_id)
        if oid in seen:
            raise InputError(root / "scene.json", f"object ids collide after sanitizing: {obj.object_id!r}")
        seen.add(oid)
        art = obj.articulation
        if not (art.lower <= 0.0 <= art.upper) or art.upper - art.lower <= 0:
            raise InputError(root / "scene.json", f"object {obj.object_id}: joint limits [{art.lower}, {art.upper}] must satisfy lower <= 0 <= upper, lower < upper")
        part = _mesh(root, obj.part_mesh)
        assert part is not None
        inner = _mesh(root, obj.inner_mesh)
        base = _mesh(root, obj.base_mesh)
        if base is not None:
            pieces = pieces_of(base, config.max_convex_hulls)
            links.append(
                Link(
                    f"{oid}__base", np.zeros(3), [bake_texture(base, config)], pieces,
                    inertial=inertial_from_pieces(pieces, config.density_kg_m3, config.min_mass_kg), object_id=obj.object_id, role="base",
                )
            )
            parent = f"{oid}__base"
        else:
            parent = "background"
        moving = [m for m in (part, inner) if m is not None]
        budget = max(1, config.max_convex_hulls // len(moving))
        pieces = [p for m in moving for p in pieces_of(m, budget)]
        links.append(
            Link(
                f"{oid}__part", np.asarray(art.origin, float), [bake_texture(m, config) for m in moving], pieces,
                inertial=inertial_from_pieces(pieces, config.density_kg_m3, config.min_mass_kg), object_id=obj.object_id, role="part",
            )
        )
        joints.append(Joint(f"{oid}__joint", obj.object_id, parent, f"{oid}__part", art))
    return SceneModel(safe_name(scene.scene_id), links, joints)
