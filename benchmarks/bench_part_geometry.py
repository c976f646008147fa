"""Is every part a conversion found exported with geometry? Per part: its mesh's cover of its front
(``react3d_core.metrics.part_geometry``), and in each exported format a link / body / prim carrying
visual and collision meshes with faces, moved by its own joint.

    python3 benchmarks/bench_part_geometry.py OUT... [--export] [--json F]

OUT are folders written by ``react3d convert`` or ``react3d bench`` (``bench --out W`` keeps them under
``W/results/``). ``--export`` first writes URDF, MJCF and USD into each (``OUT/export``, as ``react3d
export`` does); without it the exports already there are read. Meant for scenes whose fronts the depth
sensor missed, where a part's surface comes from the slab that completes the scan.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

FORMATS = ("urdf", "mjcf", "usd")
MIN_COVER = 0.5
"""A part counts as having geometry when its mesh covers at least half its front's rectangle."""


def _faces(path: Path) -> int:
    """Triangles in a mesh file (0 when missing or unreadable)."""
    import trimesh

    if not path.is_file():
        return 0
    try:
        m = trimesh.load(path, force="mesh", process=False)
    except Exception:  # an unreadable file is a part without geometry, reported as such
        return 0
    return int(len(m.faces))


def urdf_parts(urdf: Path) -> dict[str, dict[str, Any]]:
    """Per link: faces of its visual meshes, count of non-empty collision meshes, whether a moving joint
    has it as child."""
    root = ET.parse(urdf).getroot()
    moving = {j.find("child").get("link") for j in root.iter("joint") if j.get("type") != "fixed"}
    out = {}
    for link in root.iter("link"):
        def meshes(tag: str) -> list[int]:
            return [_faces(urdf.parent / m.get("filename")) for e in link.iter(tag) for m in e.iter("mesh")]
        vis = meshes("visual")
        out[link.get("name")] = {"visual_faces": sum(vis), "collisions": sum(f > 0 for f in meshes("collision")),
                                 "jointed": link.get("name") in moving}
    return out


def mjcf_parts(xml: Path) -> dict[str, dict[str, Any]]:
    """Per body, as MuJoCo compiles it: faces of its mesh geoms that do not collide (visual), count of
    those that do (with faces), and whether the body has a joint."""
    import mujoco
    import numpy as np

    m = mujoco.MjModel.from_xml_path(str(xml))
    out = {}
    for b in range(m.nbody):
        g = np.flatnonzero((m.geom_bodyid == b) & (m.geom_type == mujoco.mjtGeom.mjGEOM_MESH))
        faces = m.mesh_facenum[m.geom_dataid[g]]
        collide = (m.geom_contype[g] | m.geom_conaffinity[g]) != 0
        out[mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)] = {
            "visual_faces": int(faces[~collide].sum()), "collisions": int(np.sum(collide & (faces > 0))),
            "jointed": bool(m.body_jntnum[b] > 0)}
    return out


def usd_parts(usd: Path) -> dict[str, dict[str, Any]]:
    """Per part prim ``/World/<id>/<id>``: points of its meshes outside ``collisions``, collision pieces,
    and whether a revolute or prismatic joint names it as body1."""
    from pxr import Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.Open(str(usd))
    jointed = set()
    for p in stage.Traverse():
        if p.IsA(UsdPhysics.RevoluteJoint) or p.IsA(UsdPhysics.PrismaticJoint):
            jointed.update(str(t) for t in UsdPhysics.Joint(p).GetBody1Rel().GetTargets())
    out = {}
    for top in stage.GetPrimAtPath("/World").GetChildren():
        part = top.GetChild(top.GetName())
        if not part:
            continue
        pts = coll = 0
        for p in Usd.PrimRange(part):
            if p.IsA(UsdGeom.Mesh):
                n = len(UsdGeom.Mesh(p).GetPointsAttr().Get() or [])
                if "/collisions/" in str(p.GetPath()):
                    coll += n > 0
                else:
                    pts += n
        out[top.GetName()] = {"visual_points": pts, "collisions": coll, "jointed": str(part.GetPath()) in jointed}
    return out


def check_output(out: Path, export: bool) -> dict[str, Any]:
    """Every part of one conversion: front cover and presence in each exported format."""
    import numpy as np

    from react3d_core.data.mesh import load_mesh
    from react3d_core.metrics.part_geometry import front_cover, front_frame

    t0 = time.perf_counter()
    if export:
        from react3d_core.export import export_scene

        export_scene(str(out), formats=FORMATS)
    scene = json.loads((out / "scene.json").read_text())
    exp = out / "export"
    per_format = {"urdf": urdf_parts(exp / "urdf" / "scene.urdf") if (exp / "urdf" / "scene.urdf").is_file() else None,
                  "mjcf": mjcf_parts(exp / "mjcf" / "scene.xml") if (exp / "mjcf" / "scene.xml").is_file() else None,
                  "usd": usd_parts(exp / "usd" / "scene.usda") if (exp / "usd" / "scene.usda").is_file() else None}
    parts = []
    for o in scene["objects"]:
        oid, obb = o["object_id"], o["obb"]
        u, v, w, h = front_frame(np.array(obb["axes"]), np.array(obb["extents"]), np.array(o["front_normal"]))
        mesh = load_mesh(out / o["part_mesh"])
        row: dict[str, Any] = {"object_id": oid, "label": o["label"], "part_faces": int(mesh.n_faces),
                               "front_m": [round(w, 3), round(h, 3)],
                               "cover": round(front_cover(mesh, np.array(obb["center"]), np.array(o["front_normal"]),
                                                          u, v, w, h), 3)}
        for fmt, links in per_format.items():
            if links is None:
                continue
            e = links.get(oid, {})
            shown = e.get("visual_faces", e.get("visual_points", 0)) > 0
            row[fmt] = bool(shown and e.get("collisions", 0) > 0 and e.get("jointed"))
        row["ok"] = row["cover"] >= MIN_COVER and all(row.get(f, True) for f in FORMATS)
        parts.append(row)
    return {"output": str(out), "scene": out.name, "formats": [f for f, v in per_format.items() if v is not None],
            "parts": parts, "seconds": round(time.perf_counter() - t0, 1)}


def main(argv: list[str] | None = None) -> int:
    import numpy as np

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outputs", nargs="+", help="conversion output folders (holding scene.json)")
    ap.add_argument("--export", action="store_true", help="write URDF, MJCF and USD into each first")
    ap.add_argument("--json", help="write the per-part results here")
    a = ap.parse_args(argv)
    rows = []
    for o in a.outputs:
        if not (Path(o) / "scene.json").is_file():
            raise SystemExit(f"{o}: no scene.json; give folders written by react3d convert")
        r = check_output(Path(o), a.export)
        rows.append(r)
        c = [p["cover"] for p in r["parts"]]
        print(f"{r['scene']:52s} parts {len(c):3d}  with geometry {sum(p['ok'] for p in r['parts']):3d}  "
              f"cover min {min(c, default=0):.2f} median {float(np.median(c)) if c else 0:.2f}  "
              f"formats {','.join(r['formats']) or '-'} ({r['seconds']} s)")
    allp = [p for r in rows for p in r["parts"]]
    total = {"parts": len(allp), "with_geometry": sum(p["ok"] for p in allp),
             "cover_median": float(np.median([p["cover"] for p in allp])) if allp else 0.0,
             "cover_below": sum(p["cover"] < MIN_COVER for p in allp),
             "missing_in_format": {f: sum(p.get(f) is False for p in allp) for f in FORMATS}}
    print(f"ALL: {total['with_geometry']} of {total['parts']} parts with geometry (cover >= {MIN_COVER} and "
          f"visual + collision + joint in every format); median cover {total['cover_median']:.2f}; "
          f"missing per format {total['missing_in_format']}")
    for r, p in ((r, p) for r in rows for p in r["parts"] if not p["ok"]):
        print(f"  without: {r['scene']} {p['object_id']} cover {p['cover']} faces {p['part_faces']} "
              + " ".join(f"{f}={p.get(f)}" for f in FORMATS))
    if a.json:
        Path(a.json).write_text(json.dumps({"outputs": rows, "total": total, "min_cover": MIN_COVER}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
