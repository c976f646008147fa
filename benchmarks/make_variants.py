"""Tessellation variants of a scene folder: the same capture with its scan mesh re-made in other triangles.

    python3 benchmarks/make_variants.py SCENE --out DIR [--quadric 100000] [--quadric 0.25] [--cluster 0.02]

Each variant is a scene folder DIR/<scene>_q<N> (quadric decimation to N faces, or to that share of them
when N <= 1) or DIR/<scene>_c<V> (vertex clustering on a V-metre grid): every file of SCENE is linked
(symbolic links, nothing copied or modified) except the scan mesh, which is written new, and the
Articulate3D ground truth, when there is one, which is moved onto the new mesh
(``react3d_core.synthetic.remesh.transfer_labels``: each new vertex takes the part of the nearest old
surface point within 1 cm, each face its vertices' majority). Perception must find the same fronts on
every variant of a capture (a user's scan app exports whatever tessellation it likes); the benchmarks
and the slow RedKitchen test build them with this. An existing variant folder is left as it is.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

GT_DIR = "articulate3d"


def variant_name(scene: Path, quadric: float | None = None, cluster: float | None = None) -> str:
    """``<scene>_q<N>`` or ``<scene>_c<V>``."""
    if (quadric is None) == (cluster is None):
        raise ValueError("a variant is either quadric-decimated or vertex-clustered")
    return f"{scene.name}_q{quadric:g}" if quadric is not None else f"{scene.name}_c{cluster:g}"


def make_variant(scene: str | Path, out_dir: str | Path, quadric: float | None = None,
                 cluster: float | None = None) -> Path:
    """Write one variant of ``scene`` under ``out_dir`` (see module docstring); returns its folder.
    The folder appears whole or not at all; an existing one is returned as it is."""
    from react3d_core.atomic import atomic_dir
    from react3d_core.data.mesh import load_mesh, save_mesh
    from react3d_core.errors import InputError
    from react3d_core.scene_io import load_scene
    from react3d_core.synthetic.remesh import cluster_vertices, decimate_to

    scene = Path(scene).resolve()
    dest = Path(out_dir) / variant_name(scene, quadric, cluster)
    if dest.is_dir():
        return dest
    mesh_path = Path(load_scene(scene).mesh_path).resolve()
    if scene not in mesh_path.parents:
        raise InputError(mesh_path, f"the scan mesh lies outside the scene folder {scene}; cannot make a variant")
    mesh = load_mesh(mesh_path)
    new = decimate_to(mesh, quadric) if quadric is not None else cluster_vertices(mesh, cluster)  # type: ignore[arg-type]
    gt = scene / GT_DIR
    with atomic_dir(dest) as tmp:
        for dirpath, dirnames, filenames in os.walk(scene):
            rel = Path(dirpath).relative_to(scene)
            if rel.parts and rel.parts[0] == GT_DIR and gt.is_dir():
                continue
            dirnames[:] = [d for d in dirnames if not d.startswith(".")]  # caches of the original stay there
            (tmp / rel).mkdir(parents=True, exist_ok=True)
            for fn in filenames:
                src = Path(dirpath) / fn
                if src.resolve() != mesh_path:
                    (tmp / rel / fn).symlink_to(src.resolve())
        save_mesh(tmp / mesh_path.relative_to(scene), new)
        if gt.is_dir():
            _transfer_gt(gt, mesh, new, tmp / GT_DIR)
    return dest


def _transfer_gt(gt_dir: Path, old, new, out: Path) -> None:
    """The ground truth of ``gt_dir`` (on mesh ``old``) moved onto ``new`` and written to ``out``."""
    from react3d_core.ground_truth.articulate3d import GroundTruth, read_articulate3d, write_articulate3d
    from react3d_core.synthetic.remesh import transfer_labels, transfer_parts

    gt = read_articulate3d(gt_dir)
    label = np.full(old.n_faces, -1, np.int64)
    for p in gt.parts:
        label[p.tri_indices] = p.part_id
    parts, _ = transfer_parts(gt.parts, transfer_labels(old, label, new))
    write_articulate3d(out, GroundTruth(gt.scene_id, parts, new.n_faces, new.n_vertices))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", type=Path)
    ap.add_argument("--out", type=Path, required=True, help="folder the variants are written under")
    ap.add_argument("--quadric", type=float, action="append", default=[],
                    help="quadric decimation to this many faces (> 1) or this share of them (<= 1); repeatable")
    ap.add_argument("--cluster", type=float, action="append", default=[],
                    help="vertex clustering on a grid of this size (m); repeatable")
    args = ap.parse_args(argv)
    if not args.scene.is_dir():
        print(f"scene folder not found: {args.scene}", file=sys.stderr)
        return 2
    if not args.quadric and not args.cluster:
        print("nothing to make: give --quadric and/or --cluster", file=sys.stderr)
        return 2
    from react3d_core.data.mesh import load_mesh
    from react3d_core.scene_io import load_scene

    for q in args.quadric:
        d = make_variant(args.scene, args.out, quadric=q)
        print(f"{d}: {load_mesh(load_scene(d).mesh_path).n_faces} faces")
    for c in args.cluster:
        d = make_variant(args.scene, args.out, cluster=c)
        print(f"{d}: {load_mesh(load_scene(d).mesh_path).n_faces} faces")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
