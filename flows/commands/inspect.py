"""``react3d inspect SCENE``: what a scan folder holds, and whether it can be converted (exit != 0 if not)."""

from __future__ import annotations

import argparse

HELP = "Inspect a scan folder: layout, frames, resolutions, depth coverage, mesh size/bounds, GT, problems."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", help="Scene folder (ScanNet++ iPhone, prepared, or mesh + transforms.json).")
    p.add_argument("--sample", type=int, default=5, help="Frames sampled (evenly) for depth coverage.")


def summarize(scene_dir: str, sample: int = 5) -> tuple[list[tuple[str, str]], list[str]]:
    """Rows (field, value) and problems for a scene folder; raises InputError on unreadable input.

    Kept separate from printing so tests check the numbers, not the table layout."""
    import numpy as np

    from react3d_core.data.mesh import load_mesh
    from react3d_core.scene_io import load_scene
    from react3d_core.scene_io.images import read_depth

    scene = load_scene(scene_dir)
    problems = list(scene.notes)
    mesh = load_mesh(scene.mesh_path)
    if mesh.n_faces == 0:
        problems.append(f"{scene.mesh_path}: mesh has no faces")
    f0 = scene.frames[0]
    idx = np.unique(np.linspace(0, len(scene.frames) - 1, max(1, sample)).round().astype(int))
    cover = []
    for i in idx:
        ref = scene.frames[i].depth
        if ref is not None:
            cover.append(float((read_depth(ref, scene.frames[i].depth_scale) > 0).mean()))
    lo, hi = mesh.bounds()
    rows = [
        ("layout", scene.source_format),
        ("frames", str(len(scene.frames))),
        ("RGB resolution", f"{f0.intrinsics.width}x{f0.intrinsics.height}"),
        ("depth resolution", f"{f0.depth_intrinsics.width}x{f0.depth_intrinsics.height}" if f0.depth_intrinsics else "none"),
        ("depth coverage", f"{100 * np.mean(cover):.1f}% (mean of {len(cover)} frames)" if cover else "n/a"),
        ("mesh", f"{mesh.n_vertices} vertices, {mesh.n_faces} faces"),
        ("bounds (m)", f"[{lo[0]:.2f} {lo[1]:.2f} {lo[2]:.2f}] .. [{hi[0]:.2f} {hi[1]:.2f} {hi[2]:.2f}]"),
        ("GT", str(scene.gt_dir) if scene.gt_dir else "none"),
        ("GT part-id images", str(sum(f.part_ids is not None for f in scene.frames))),
        ("problems", "; ".join(problems) if problems else "none"),
    ]
    return rows, problems


def run(args: argparse.Namespace) -> int:
    from flows.commands._console import wide_console
    from rich.table import Table

    rows, problems = summarize(args.scene, args.sample)
    table = Table(title=f"react3d inspect {args.scene}", show_header=False)
    table.add_column("field", style="bold")
    table.add_column("value")
    for k, v in rows:
        table.add_row(k, v)
    wide_console().print(table)
    return 1 if problems else 0
