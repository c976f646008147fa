"""Checks of an exported USD stage that UsdValidation does not make (it only sees structure):
joint bodies exist, body0/body1 joint frames agree, one articulation root per articulation, no
triangle mesh on a moving body, positive masses, textures bound and present.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

CONVEX = {"convexHull", "convexDecomposition", "boundingCube", "boundingSphere"}


def _gf_to_np(m) -> np.ndarray:  # noqa: ANN001
    return np.array(m, dtype=float).T  # Gf matrices are row-vector: transpose to column convention


def joint_world_frame(stage, joint_prim, side: int) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """World (origin, 3x3 rotation) of a joint frame as seen from body0 (side 0) or body1 (side 1)."""
    from pxr import Usd, UsdGeom, UsdPhysics

    joint = UsdPhysics.Joint(joint_prim)
    rel = joint.GetBody0Rel() if side == 0 else joint.GetBody1Rel()
    targets = rel.GetTargets()
    T = np.eye(4)
    if targets:
        body = stage.GetPrimAtPath(targets[0])
        T = _gf_to_np(UsdGeom.Xformable(body).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
    pos = np.array((joint.GetLocalPos0Attr() if side == 0 else joint.GetLocalPos1Attr()).Get() or (0, 0, 0), float)
    q = (joint.GetLocalRot0Attr() if side == 0 else joint.GetLocalRot1Attr()).Get()
    if q is None:
        R = np.eye(3)
    else:
        from scipy.spatial.transform import Rotation

        im = q.GetImaginary()
        R = Rotation.from_quat([im[0], im[1], im[2], q.GetReal()]).as_matrix()
    return T[:3, :3] @ pos + T[:3, 3], T[:3, :3] @ R


def joint_axis_world(stage, joint_prim) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """World origin and axis of a revolute/prismatic joint from body0's local frame."""
    from pxr import UsdPhysics

    o, R = joint_world_frame(stage, joint_prim, 0)
    token = UsdPhysics.RevoluteJoint(joint_prim).GetAxisAttr().Get() if joint_prim.IsA(UsdPhysics.RevoluteJoint) else UsdPhysics.PrismaticJoint(joint_prim).GetAxisAttr().Get()
    return o, R[:, "XYZ".index(str(token))]


def usd_validation_errors(stage) -> list[str]:  # noqa: ANN001
    """Messages of every registered UsdValidation validator (empty when the stage is clean)."""
    from pxr import UsdValidation

    reg = UsdValidation.ValidationRegistry()
    ctx = UsdValidation.ValidationContext(reg.GetOrLoadAllValidators())
    return [f"{e.GetName()}: {e.GetMessage()}" for e in ctx.Validate(stage)]


def check_usd(path: str | Path, pos_tol: float = 1e-3, angle_tol_deg: float = 0.1) -> list[str]:
    """Problems found in the stage at ``path`` (empty list = all checks pass)."""
    from pxr import Usd, UsdGeom, UsdPhysics, UsdShade

    stage = Usd.Stage.Open(str(path))
    problems: list[str] = []
    if not stage.HasAuthoredMetadata("metersPerUnit") or not stage.HasAuthoredMetadata("upAxis"):
        problems.append("stage lacks metersPerUnit/upAxis")
    if not stage.HasAuthoredMetadata("kilogramsPerUnit"):
        problems.append("stage lacks kilogramsPerUnit")
    prims = list(stage.Traverse())
    bodies = {p.GetPath() for p in prims if p.HasAPI(UsdPhysics.RigidBodyAPI)}
    for p in prims:
        if not p.IsA(UsdPhysics.Joint):
            continue
        j = UsdPhysics.Joint(p)
        for rel in (j.GetBody0Rel(), j.GetBody1Rel()):
            for t in rel.GetTargets():
                if t not in bodies:
                    problems.append(f"{p.GetPath()}: {rel.GetName()} -> {t} is not a rigid body")
        o0, R0 = joint_world_frame(stage, p, 0)
        o1, R1 = joint_world_frame(stage, p, 1)
        if np.linalg.norm(o0 - o1) > pos_tol:
            problems.append(f"{p.GetPath()}: body0/body1 frame origins differ by {np.linalg.norm(o0 - o1):.4g} m")
        cos = np.clip((np.trace(R0.T @ R1) - 1) / 2, -1, 1)
        if np.degrees(np.arccos(cos)) > angle_tol_deg:
            problems.append(f"{p.GetPath()}: body0/body1 frames differ by {np.degrees(np.arccos(cos)):.4g} deg")
    for b in bodies:
        prim = stage.GetPrimAtPath(b)
        roots = [a for a in b.GetAncestorsRange() if stage.GetPrimAtPath(a).HasAPI(UsdPhysics.ArticulationRootAPI)]
        if len(roots) != 1:
            problems.append(f"{b}: {len(roots)} articulation roots above it (want 1)")
        mass = UsdPhysics.MassAPI(prim).GetMassAttr().Get() if prim.HasAPI(UsdPhysics.MassAPI) else None
        if mass is None or mass <= 0:
            problems.append(f"{b}: mass {mass} is not > 0")
        for d in Usd.PrimRange(prim):
            if d.IsA(UsdGeom.Mesh) and d.HasAPI(UsdPhysics.CollisionAPI):
                approx = UsdPhysics.MeshCollisionAPI(d).GetApproximationAttr().Get() if d.HasAPI(UsdPhysics.MeshCollisionAPI) else "none"
                if str(approx) not in CONVEX:
                    problems.append(f"{d.GetPath()}: triangle-mesh collider on a moving body (approximation {approx})")
    folder = Path(path).parent
    for p in prims:
        if not p.IsA(UsdGeom.Mesh) or p.HasAPI(UsdPhysics.CollisionAPI):
            continue
        mat, _ = UsdShade.MaterialBindingAPI(p).ComputeBoundMaterial()
        if not mat:
            problems.append(f"{p.GetPath()}: visual mesh without a bound material")
            continue
        files = [
            s.GetInput("file").Get()
            for s in (UsdShade.Shader(c) for c in Usd.PrimRange(mat.GetPrim()))
            if s and s.GetIdAttr().Get() == "UsdUVTexture"
        ]
        if not files or not all((folder / f.path).is_file() for f in files):
            problems.append(f"{p.GetPath()}: bound texture missing ({[f.path for f in files]})")
        if not UsdGeom.PrimvarsAPI(p).HasPrimvar("st"):
            problems.append(f"{p.GetPath()}: no st primvar")
    return problems
