"""Texture-baking benchmark: a ~1M-face room background and a part-sized mesh.

    python3 benchmarks/bench_texture.py --faces 1000000 --json bench_texture.json [--export]

Builds a room (floor, four walls, ceiling) of ~``--faces`` triangles with smooth vertex colours plus
per-vertex noise, bakes it with the default ExportConfig (per-triangle cell atlas above
``xatlas_max_faces``) and a 5k-face part with xatlas, then writes the OBJ+MTL+PNG. Reports wall
times, texture sizes and the mean colour error at vertex positions (bilinear lookup, 0..255 units).
Targets: background bake <= 60 s on 2 cores, mean error <= 3/255. With ``--export`` the room plus
one door becomes an InteractiveScene that is exported to URDF/USD/MJCF (timed), then loaded in
PyBullet and MuJoCo (timed).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from react3d_core.atomic import write_json  # noqa: E402


def room(n_faces: int, seed: int = 0):  # noqa: ANN201
    """A 6 x 5 x 2.6 m box room of about ``n_faces`` triangles with smooth, noisy vertex colours."""
    from react3d_core.data import TriMesh

    rng = np.random.default_rng(seed)
    sx, sy, sz = 6.0, 5.0, 2.6
    planes = [  # origin, u, v
        ((0, 0, 0), (sx, 0, 0), (0, sy, 0)), ((0, 0, sz), (0, sy, 0), (sx, 0, 0)),
        ((0, 0, 0), (0, 0, sz), (sx, 0, 0)), ((0, sy, 0), (sx, 0, 0), (0, 0, sz)),
        ((0, 0, 0), (0, sy, 0), (0, 0, sz)), ((sx, 0, 0), (0, 0, sz), (0, sy, 0)),
    ]
    area = 2 * (sx * sy + sx * sz + sy * sz)
    verts, faces, off = [], [], 0
    for o, u, v in planes:
        o, u, v = (np.asarray(x, float) for x in (o, u, v))
        frac = np.linalg.norm(u) * np.linalg.norm(v) / area
        n = max(1, int(round(np.sqrt(n_faces * frac / 2))))
        s = np.linspace(0, 1, n + 1)
        a, b = np.meshgrid(s, s, indexing="ij")
        verts.append(o + a.reshape(-1, 1) * u + b.reshape(-1, 1) * v)
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1) + off
        q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
        faces.append(np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]))
        off += (n + 1) ** 2
    V = np.concatenate(verts)
    V = V + rng.normal(scale=0.002, size=V.shape)
    col = np.stack([128 + 90 * np.sin(2 * V[:, 0]), 128 + 90 * np.cos(3 * V[:, 1]), 60 + 60 * V[:, 2]], 1)
    col = col + rng.normal(scale=8, size=col.shape)
    return TriMesh(V, np.concatenate(faces), np.clip(np.round(col), 0, 255).astype(np.uint8))


def time_export(bg) -> dict[str, float | int | str]:  # noqa: ANN001
    """export_scene on ``bg`` + one revolute door, then load the URDF (PyBullet) and MJCF (MuJoCo)."""
    import trimesh

    from react3d_core.data import OBB, Articulation, InteractiveObject, InteractiveScene, TriMesh, save_mesh
    from react3d_core.export import export_scene

    rows: dict[str, float | int | str] = {}
    with tempfile.TemporaryDirectory() as d:
        root = Path(d)
        save_mesh(root / "meshes" / "background.ply", bg)
        door = trimesh.creation.box(extents=(0.5, 0.02, 0.7)).apply_translation((1.25, 0.3, 0.5))
        save_mesh(root / "meshes" / "door" / "part.ply", TriMesh(door.vertices, door.faces))
        art = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(1.0, 0.3, 0.5), lower=0.0, upper=1.5)
        obj = InteractiveObject(
            object_id="door", articulation=art, front_normal=(0, 1, 0), part_mesh="meshes/door/part.ply",
            obb=OBB(center=(1.25, 0.3, 0.5), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.7, 0.5, 0.02)),
        )
        InteractiveScene(scene_id="bench", input_mesh="meshes/background.ply", background_mesh="meshes/background.ply", objects=[obj]).save(root / "scene.json")
        t = time.perf_counter()
        out = export_scene(root / "scene.json")
        rows["export urdf+usd+mjcf s"] = round(time.perf_counter() - t, 2)
        import mujoco
        import pybullet as pb

        t = time.perf_counter()
        cid = pb.connect(pb.DIRECT)
        pb.loadURDF(str(out["urdf"]), useFixedBase=True, physicsClientId=cid)
        pb.disconnect(cid)
        rows["PyBullet load s"] = round(time.perf_counter() - t, 2)
        t = time.perf_counter()
        model = mujoco.MjModel.from_xml_path(str(out["mjcf"]))
        rows["MuJoCo compile s"] = round(time.perf_counter() - t, 2)
        rows["MuJoCo geoms"] = int(model.ngeom)
        rows["export size MB"] = round(sum(f.stat().st_size for f in (root / "export").rglob("*") if f.is_file()) / 1e6, 1)
    return rows


def _bake_rows(name: str, mesh, cfg, rows: dict):  # noqa: ANN001, ANN202
    """Bake ``mesh`` and record time, method, texture size and colour error under ``name``."""
    from react3d_core.texture import bake_texture, vertex_color_error

    t = time.perf_counter()
    tm = bake_texture(mesh, cfg)
    rows[f"{name} bake s"] = round(time.perf_counter() - t, 2)
    rows[f"{name} method"] = tm.method
    rows[f"{name} texture"] = f"{tm.image.shape[1]}x{tm.image.shape[0]}"
    rows[f"{name} mean colour error /255"] = round(vertex_color_error(tm, mesh), 3)
    return tm


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--faces", type=int, default=1_000_000)
    p.add_argument("--part-faces", type=int, default=5000)
    p.add_argument("--json", default=None)
    p.add_argument("--export", action="store_true", help="Also time export_scene on the room + a door and simulator loading.")
    a = p.parse_args(argv)

    from react3d_core.config.export import ExportConfig
    from react3d_core.texture import write_obj_folder

    cfg = ExportConfig()
    rows: dict[str, float | int | str] = {}
    bg = room(a.faces)
    rows["background faces"] = bg.n_faces
    tm = _bake_rows("background", bg, cfg, rows)
    with tempfile.TemporaryDirectory() as d:
        t = time.perf_counter()
        write_obj_folder(tm, Path(d) / "bg")
        rows["background OBJ+PNG write s"] = round(time.perf_counter() - t, 2)

    import trimesh

    from react3d_core.data import TriMesh

    sub = max(1, int(np.ceil(np.log(a.part_faces / 20) / np.log(4))))
    sphere = trimesh.creation.icosphere(subdivisions=sub, radius=0.3)
    v = np.asarray(sphere.vertices)
    part = TriMesh(v, sphere.faces, np.clip(128 + 300 * v, 0, 255).astype(np.uint8))
    rows["part faces"] = part.n_faces
    _bake_rows("part", part, cfg, rows)

    if a.export:
        rows.update(time_export(bg))

    from rich.console import Console
    from rich.table import Table

    table = Table(title="texture baking")
    table.add_column("measure")
    table.add_column("value", justify="right")
    for k, val in rows.items():
        table.add_row(k, str(val))
    Console().print(table)
    if a.json:
        write_json(a.json, rows)
    ok = float(rows["background bake s"]) <= 60 and float(rows["background mean colour error /255"]) <= 3
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
