"""USD writer (usd-core, UsdPhysics): one stage in metres, z up, kilograms.

Per object: an Xform ``/World/<object>`` carrying ``ArticulationRootAPI`` (exactly one root per
articulation) holding the carcass body ``<object>_base`` fixed to the world, the part body ``<object>``
and its revolute/prismatic joint ``<object>_joint`` (the URDF's and MJCF's link and joint names). UsdPhysics
joint axes are only X/Y/Z, so both local joint frames are rotated to map +X onto the articulation
axis (an axis near -X uses a half turn about Z, where the shortest-arc formula breaks down); body0's
and body1's frames are the same world frame, so PhysX does not move bodies at load. Moving bodies
get convex colliders only; the static background collides through its own visual triangle mesh (one
copy of the scan in the file, not two), less the faces in a part's path or inside a carcass (written
as a second, visual-only prim). Collision policy, stated in the file: each articulation root applies
``PhysxArticulationAPI`` with ``physxArticulation:enabledSelfCollisions = true`` (authored by name:
PhysxSchema is not in usd-core); every joint has ``physics:collisionEnabled = false`` (a part never
collides with its own carcass, as in PyBullet with parent exclusion and the MJCF's ``<exclude>``);
each carcass filters the background (``FilteredPairsAPI``: two static bodies). Everything else
collides, a robot included. Mesh data lives inside the stage (usd-core cannot reference
OBJ/GLB), written as a binary crate ``scene.usdc`` (~4x smaller than ASCII) under a small
``scene.usda`` root that carries the stage metadata and sublayers it. Textures are the shared
export assets (``../assets/<link>/visual_<k>/material_0.png``), bound through UsdPreviewSurface +
UsdUVTexture + a ``st`` primvar reader.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..atomic import atomic_path
from ..config.export import ExportConfig
from .assets import LinkFiles
from .collision import ConvexPiece
from .model import Link, SceneModel


def align_x(axis: np.ndarray) -> np.ndarray:
    """Rotation matrix R with R @ e_x = axis (unit)."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    c = float(a[0])
    if c < -1.0 + 1e-9:
        return np.diag([-1.0, -1.0, 1.0])  # half turn about z
    v = np.array([0.0, -a[2], a[1]])  # e_x x a
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def _quatf(R: np.ndarray):  # noqa: ANN202
    from pxr import Gf

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return Gf.Quatf(float(w), Gf.Vec3f(float(x), float(y), float(z)))


def _vec3f(v: np.ndarray):  # noqa: ANN202
    from pxr import Gf

    return Gf.Vec3f(*(float(x) for x in v))


def _define_mesh(stage, path: str, vertices: np.ndarray, faces: np.ndarray):  # noqa: ANN001, ANN202
    from pxr import UsdGeom, Vt

    mesh = UsdGeom.Mesh.Define(stage, path)
    pts = np.ascontiguousarray(vertices, np.float32)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.ascontiguousarray(faces, np.int32).ravel()))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([pts.min(0), pts.max(0)])))
    return mesh


def _material(stage, name: str, texture_rel: str):  # noqa: ANN001, ANN202
    from pxr import Sdf, UsdShade

    root = f"/World/Looks/{name}"
    mat = UsdShade.Material.Define(stage, root)
    pbr = UsdShade.Shader.Define(stage, f"{root}/PreviewSurface")
    pbr.CreateIdAttr("UsdPreviewSurface")
    pbr.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.8)
    pbr.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(0.0)
    reader = UsdShade.Shader.Define(stage, f"{root}/stReader")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
    tex = UsdShade.Shader.Define(stage, f"{root}/diffuseTexture")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(texture_rel))
    tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    tex.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("clamp")
    tex.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("clamp")
    tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    pbr.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(tex.ConnectableAPI(), "rgb")
    mat.CreateSurfaceOutput().ConnectToSource(pbr.ConnectableAPI(), "surface")
    return mat


def _visuals(stage, prim_path: str, link: Link, files: LinkFiles, face_sets: list[tuple[str, np.ndarray]] | None = None) -> list:  # noqa: ANN001
    """Textured visual meshes of ``link`` (textures: the shared asset files); returns the mesh prims.

    ``face_sets``: (name suffix, face ids) — each visual is written as one prim per set (sharing its
    material), so part of a surface can collide and the rest not without a second copy of it."""
    from pxr import Sdf, UsdGeom, UsdShade, Vt

    meshes = []
    for k, tm in enumerate(link.visuals):
        name = f"{link.name}_visual_{k}"
        material = _material(stage, name, files.textures[k])
        subsets = [(name, np.arange(len(tm.faces)))] if face_sets is None else [(f"{name}{suffix}", ids) for suffix, ids in face_sets]
        for prim_name, ids in subsets:
            if not len(ids):
                continue
            faces = tm.faces[ids]
            # scan topology (shared points) with face-varying st: UV seams need no duplicated points
            used, first, inv = np.unique(tm.source_vertex[faces.ravel()], return_index=True, return_inverse=True)
            mesh = _define_mesh(stage, f"{prim_path}/{prim_name}", tm.vertices[faces.ravel()[first]] - link.frame, inv.reshape(-1, 3))
            st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying)
            st.Set(Vt.Vec2fArray.FromNumpy(np.ascontiguousarray(tm.uv[faces].reshape(-1, 2), np.float32)))
            UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
            meshes.append(mesh)
    return meshes


def _colliders(stage, prim_path: str, pieces: list[ConvexPiece], frame: np.ndarray) -> None:  # noqa: ANN001
    from pxr import Gf, UsdGeom, UsdPhysics

    for k, piece in enumerate(pieces):
        # points around the piece's own centre, the prim moved there (see ConvexPiece.centre)
        mesh = _define_mesh(stage, f"{prim_path}/collisions/piece_{k}", piece.vertices - piece.centre, piece.faces)
        mesh.AddTranslateOp().Set(Gf.Vec3d(*map(float, piece.centre - frame)))
        mesh.CreatePurposeAttr(UsdGeom.Tokens.guide)
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr(UsdPhysics.Tokens.convexHull)


def _background(stage, bg: Link, files: LinkFiles) -> list:  # noqa: ANN001
    """The background's visuals; the faces that collide (not in a part's path nor in a carcass) carry
    a static triangle-mesh collider, the rest is visual only, and fragments of big faces that were
    only partly in the way become one more guide mesh. Returns the collider prim paths."""
    from pxr import UsdGeom, UsdPhysics

    keep = bg.collide_faces
    sets = None if keep is None else [("", np.flatnonzero(keep)), ("_visual_only", np.flatnonzero(~keep))]
    colliders = []
    for mesh in _visuals(stage, "/World/background", bg, files, sets):
        if mesh.GetPrim().GetName().endswith("_visual_only"):
            continue
        # static triangle collider = the visual scan mesh itself (same triangles; no second copy)
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr(UsdPhysics.Tokens.none)
        colliders.append(mesh.GetPath())
    if bg.fragments is not None and len(bg.fragments):
        frags = bg.fragments.reshape(-1, 3) - bg.frame
        mesh = _define_mesh(stage, "/World/background/collision_fragments", frags, np.arange(len(frags)).reshape(-1, 3))
        mesh.CreatePurposeAttr(UsdGeom.Tokens.guide)
        UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
        UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr(UsdPhysics.Tokens.none)
        colliders.append(mesh.GetPath())
    return colliders


PHYSX_ARTICULATION_API = "PhysxArticulationAPI"
"""PhysX's articulation schema (PhysxSchema, not part of usd-core): applied by its token, its attribute authored by name."""
SELF_COLLISIONS = "physxArticulation:enabledSelfCollisions"


def _self_collisions(prim, enabled: bool) -> None:  # noqa: ANN001
    """State the articulation's self-collision policy for PhysX (Isaac Sim): links of one articulation
    collide unless jointed to each other (PhysX never collides a joint's two bodies by default)."""
    from pxr import Sdf

    prim.AddAppliedSchema(PHYSX_ARTICULATION_API)
    prim.CreateAttribute(SELF_COLLISIONS, Sdf.ValueTypeNames.Bool, custom=False).Set(bool(enabled))


def _body(stage, path: str, link: Link, files: LinkFiles):  # noqa: ANN001, ANN202
    from pxr import UsdGeom, UsdPhysics

    xf = UsdGeom.Xform.Define(stage, path)
    xf.AddTranslateOp().Set(tuple(float(x) for x in link.frame))
    UsdPhysics.RigidBodyAPI.Apply(xf.GetPrim())
    inn = link.inertial
    if inn is not None:
        mass = UsdPhysics.MassAPI.Apply(xf.GetPrim())
        mass.CreateMassAttr(float(inn.mass))
        mass.CreateCenterOfMassAttr(_vec3f(inn.com - link.frame))
        mass.CreateDiagonalInertiaAttr(_vec3f(inn.moments))
        mass.CreatePrincipalAxesAttr(_quatf(inn.axes))
    _visuals(stage, path, link, files)
    _colliders(stage, path, link.collisions, link.frame)
    return xf


def _write_root(path: Path, data_name: str) -> None:
    """The small ASCII root: stage metadata (read from the root layer only) and a sublayer to the crate."""
    from pxr import Sdf, UsdGeom, UsdPhysics

    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.subLayerPaths.append(f"./{data_name}")
    layer.defaultPrim = "World"
    layer.pseudoRoot.SetInfo(UsdGeom.Tokens.upAxis, UsdGeom.Tokens.z)
    layer.pseudoRoot.SetInfo(UsdGeom.Tokens.metersPerUnit, 1.0)
    layer.pseudoRoot.SetInfo(UsdPhysics.Tokens.kilogramsPerUnit, 1.0)
    with atomic_path(path) as tmp:
        if not layer.Export(str(tmp)):
            raise OSError(f"cannot write {path}")


def write_usd(model: SceneModel, path: str | Path, config: ExportConfig, files: dict[str, LinkFiles]) -> Path:
    """Write the stage for ``model`` at ``path``; returns the file to open.

    ``path`` ending in ``.usda`` with ``config.usd_binary``: the stage goes to ``scene.usdc`` beside
    it and ``path`` becomes the small root (``config.usd_ascii_root``). Texture paths come from
    ``files`` (relative to ``path``'s folder)."""
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

    path = Path(path)
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdPhysics.SetStageKilogramsPerUnit(stage, 1.0)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    scene = UsdPhysics.Scene.Define(stage, "/World/PhysicsScene")
    scene.CreateGravityDirectionAttr(Gf.Vec3f(0, 0, -1))
    scene.CreateGravityMagnitudeAttr(9.81)

    bg = model.link("background")
    UsdGeom.Xform.Define(stage, "/World/background")
    background_colliders = _background(stage, bg, files["background"])

    for j in model.joints:
        oid = j.child  # the part link is named after its object
        root = f"/World/{oid}"
        UsdGeom.Xform.Define(stage, root)
        UsdPhysics.ArticulationRootAPI.Apply(stage.GetPrimAtPath(root))
        _self_collisions(stage.GetPrimAtPath(root), True)
        parent = model.link(j.parent)
        part = model.link(j.child)
        body0: str | None = None
        if parent.role == "base":
            body0 = f"{root}/{parent.name}"
            _body(stage, body0, parent, files[parent.name])
            # static against static: the carcass never moves, so contacts with the background would only cost
            UsdPhysics.FilteredPairsAPI.Apply(stage.GetPrimAtPath(body0)).CreateFilteredPairsRel().SetTargets(background_colliders)
            fixed = UsdPhysics.FixedJoint.Define(stage, f"{root}/{parent.name}_fixed")
            fixed.CreateCollisionEnabledAttr(False)
            fixed.CreateBody1Rel().SetTargets([Sdf.Path(body0)])
            fixed.CreateLocalPos0Attr(_vec3f(parent.frame))
            fixed.CreateLocalRot0Attr(Gf.Quatf(1.0))
            fixed.CreateLocalPos1Attr(Gf.Vec3f(0, 0, 0))
            fixed.CreateLocalRot1Attr(Gf.Quatf(1.0))
        body1 = f"{root}/{part.name}"
        _body(stage, body1, part, files[part.name])
        a = j.articulation
        revolute = a.joint_type == "revolute"
        joint = (UsdPhysics.RevoluteJoint if revolute else UsdPhysics.PrismaticJoint).Define(stage, f"{root}/{j.name}")
        joint.CreateAxisAttr(UsdPhysics.Tokens.x)
        joint.CreateCollisionEnabledAttr(False)  # a part and its own carcass never collide (as in URDF engines and the MJCF)
        if body0 is not None:
            joint.CreateBody0Rel().SetTargets([Sdf.Path(body0)])
        joint.CreateBody1Rel().SetTargets([Sdf.Path(body1)])
        R = _quatf(align_x(np.asarray(a.axis)))
        origin0 = part.frame - (parent.frame if body0 is not None else np.zeros(3))
        joint.CreateLocalPos0Attr(_vec3f(origin0))
        joint.CreateLocalRot0Attr(R)
        joint.CreateLocalPos1Attr(Gf.Vec3f(0, 0, 0))
        joint.CreateLocalRot1Attr(R)
        scale = 180.0 / math.pi if revolute else 1.0
        joint.CreateLowerLimitAttr(float(a.lower * scale))
        joint.CreateUpperLimitAttr(float(a.upper * scale))
        if j.damping > 0:
            drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular" if revolute else "linear")
            drive.CreateTypeAttr("force")
            drive.CreateStiffnessAttr(0.0)
            drive.CreateDampingAttr(float(j.damping / scale))  # per degree for revolute
            drive.CreateMaxForceAttr(float(config.joint_effort))
    # a .usdc path is the stage itself; a .usda path is the root over a crate (binary) or the stage (ASCII)
    data = path.with_suffix(".usdc") if config.usd_binary else path
    with atomic_path(data) as tmp:
        if not stage.GetRootLayer().Export(str(tmp)):
            raise OSError(f"cannot write {data}")
    if data != path:
        _write_root(path, data.name)
    return path
