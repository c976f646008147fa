"""Ablation: articulation refinement on vs off, on synthetic scenes with oracle segmentation.

    python3 benchmarks/ablation_refinement.py --scenes 5 --json ablation_refinement.json
    python3 benchmarks/ablation_refinement.py --scene-dir /path/to/synthetic_scene ...

Candidates are the GT part vertex sets, each with its handle (what segmentation hands over). The
initial joint is the GT joint with OPDMulti-like noise: the axis tilted by ``axis_noise_deg`` (7 deg) in a
random direction and the origin moved by ``origin_noise_m`` (0.2 m) in a random direction; the joint
type is kept, so every part is a correct-type match. The front normal is oriented away from the nearest
camera that looks at the part (a stand-in for the segmenting view). Refinement is the stage's own
``fit_part`` + ``refine_articulation``. OE: axis angle (deg); MD: distance between the joint lines (m),
revolute joints only (a prismatic origin is arbitrary).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from react3d_core.articulation import ArticulatedPart, fit_part, refine_articulation  # noqa: E402
from react3d_core.config import PipelineConfig  # noqa: E402
from react3d_core.data.frames import SceneInput  # noqa: E402
from react3d_core.data.mesh import TriMesh, load_mesh  # noqa: E402
from react3d_core.data.parts import Articulation  # noqa: E402
from react3d_core.ground_truth.articulate3d import read_articulate3d  # noqa: E402
from react3d_core.metrics.geometry import axis_error_deg, line_distance  # noqa: E402
from react3d_core.scene_io import load_scene  # noqa: E402


def perturb(gt: Articulation, rng: np.random.Generator, axis_noise_deg: float, origin_noise_m: float) -> Articulation:
    """The GT joint with its axis tilted by exactly ``axis_noise_deg`` and origin moved by ``origin_noise_m``."""
    a = np.asarray(gt.axis, float) / np.linalg.norm(gt.axis)
    r = rng.normal(size=3)
    perp = np.cross(a, r)
    perp /= np.linalg.norm(perp)
    t = np.radians(axis_noise_deg)
    axis = np.cos(t) * a + np.sin(t) * perp
    d = rng.normal(size=3)
    origin = np.asarray(gt.origin, float) + origin_noise_m * d / np.linalg.norm(d)
    return gt.model_copy(update={"axis": tuple(axis), "origin": tuple(origin)})


def joint_errors(pred: Articulation, gt: Articulation) -> tuple[float, float | None]:
    oe = axis_error_deg(np.asarray(pred.axis), np.asarray(gt.axis))
    if gt.joint_type != "revolute":
        return oe, None
    return oe, line_distance(np.asarray(pred.origin), np.asarray(pred.axis), np.asarray(gt.origin), np.asarray(gt.axis))


def _camera_for(centers: np.ndarray, dirs: np.ndarray, point: np.ndarray) -> int:
    """Index of the nearest camera whose optical axis points at ``point`` (within 60 deg)."""
    v = point - centers
    dist = np.linalg.norm(v, axis=1)
    facing = (v * dirs).sum(1) / np.maximum(dist, 1e-9) > 0.5
    idx = np.flatnonzero(facing) if facing.any() else np.arange(len(centers))
    return int(idx[np.argmin(dist[idx])])


def oracle_parts(scene_dir: str | Path, seed: int = 0, axis_noise_deg: float = 7.0, origin_noise_m: float = 0.2,
                 config: PipelineConfig | None = None, refine: bool = True, vertex_noise_m: float = 0.0,
                 ) -> tuple[SceneInput, TriMesh, list[tuple[ArticulatedPart, Articulation]]]:
    """Oracle segmentation of a synthetic scene: one ``ArticulatedPart`` per GT movable part (with its
    handle), initial joint = noisy GT, refined by the stage's code; paired with the GT joint.
    ``vertex_noise_m``: Gaussian noise on the part's points before fitting (scan noise)."""
    cfg = config or PipelineConfig()
    scene_dir = Path(scene_dir)
    scene = load_scene(scene_dir)
    mesh = load_mesh(scene.mesh_path)
    gt = read_articulate3d(scene_dir / "articulate3d")
    meta = json.loads((scene_dir / "synth_meta.json").read_text())
    handle_of = {p["part_id"]: p.get("handle_part_id") for p in meta["parts"]}
    by_id = {p.part_id: p for p in gt.parts}
    centers = np.array([f.c2w[:3, 3] for f in scene.frames])
    dirs = np.array([f.c2w[:3, 2] for f in scene.frames])
    rng = np.random.default_rng(seed)
    out = []
    for p in gt.parts:
        if p.articulation is None:
            continue
        vids, fids = p.vert_indices, p.tri_indices
        h = by_id.get(handle_of.get(p.part_id, -1))
        if h is not None:
            vids, fids = np.union1d(vids, h.vert_indices), np.union1d(fids, h.tri_indices)
        pts = mesh.vertices[vids] + (rng.normal(0.0, vertex_noise_m, (len(vids), 3)) if vertex_noise_m > 0 else 0.0)
        cam = _camera_for(centers, dirs, pts.mean(0))
        fit = fit_part(pts, centers[cam], None, cfg.articulation.flat_ratio)
        initial = perturb(p.articulation, rng, axis_noise_deg, origin_noise_m)
        art = refine_articulation(initial, fit, refine)
        part = ArticulatedPart(candidate_id=p.part_id, label=p.label, score=1.0, face_ids=fids, vertex_ids=vids,
                               initial=initial, articulation=art, obb=fit.obb, front_normal=fit.front_normal,
                               thickness=fit.thickness, flat=fit.flat, seg_frame_id=scene.frames[cam].frame_id)
        out.append((part, p.articulation))
    return scene, mesh, out


def ablate_scene(scene_dir: str | Path, seed: int = 0, axis_noise_deg: float = 7.0, origin_noise_m: float = 0.2,
                 config: PipelineConfig | None = None, vertex_noise_m: float = 0.0) -> list[dict]:
    """One row per GT movable part: errors with and without refinement (same noise draw)."""
    _, _, parts = oracle_parts(scene_dir, seed, axis_noise_deg, origin_noise_m, config, vertex_noise_m=vertex_noise_m)
    rows = []
    for part, gt in parts:
        oe0, md0 = joint_errors(part.initial, gt)
        oe1, md1 = joint_errors(part.articulation, gt)
        rows.append({"scene": Path(scene_dir).name, "part_id": part.candidate_id, "label": part.label,
                     "type": gt.joint_type, "flat": part.flat, "oe_off": oe0, "md_off": md0, "oe_on": oe1, "md_on": md1})
    return rows


def cavity_rows(scene_dir: str | Path, out_dir: str | Path, seed: int = 0, config: PipelineConfig | None = None) -> list[dict]:
    """Assemble the oracle parts of a scene; per object: cavity depth vs the true interior depth
    (synth_meta.json) and whether a drawer's travel stays inside its cavity."""
    from react3d_core.assembly import assemble_scene

    cfg = config or PipelineConfig()
    scene, mesh, pairs = oracle_parts(scene_dir, seed, config=cfg)
    m = assemble_scene(scene, mesh, [p for p, _ in pairs], cfg, out_dir)
    meta = json.loads((Path(scene_dir) / "synth_meta.json").read_text())
    depth_of = {p["label"]: p.get("interior_depth") for p in meta["parts"]}
    gt_label = gt_labels(m.objects, [p for p, _ in pairs])
    return [{"scene": Path(scene_dir).name, "label": gt_label[o.object_id], "type": o.articulation.joint_type,
             "cavity": o.cavity_depth, "source": o.cavity_depth_source, "true": depth_of.get(gt_label[o.object_id]),
             "err": abs(o.cavity_depth - depth_of[gt_label[o.object_id]]) if depth_of.get(gt_label[o.object_id]) is not None else None,
             "upper": o.articulation.upper, "limit_source": o.articulation.limit_source} for o in m.objects]


def gt_labels(objects: list, parts: list[ArticulatedPart]) -> dict[str, str]:
    """Object id -> the GT label of the oracle part it was assembled from (assembly names objects by
    what they are, ``drawer_02``; the part keeps its OBB)."""
    key = {tuple(np.round(p.obb.center, 6)): p.label for p in parts}
    return {o.object_id: key[tuple(np.round(o.obb.center, 6))] for o in objects}


def summarize(rows: list[dict]) -> dict[str, float | int]:
    def mean(key: str) -> float:
        v = [r[key] for r in rows if r[key] is not None]
        return float(np.mean(v)) if v else float("nan")

    return {"parts": len(rows), "revolute": sum(r["type"] == "revolute" for r in rows),
            "oe_off_deg": mean("oe_off"), "oe_on_deg": mean("oe_on"), "md_off_m": mean("md_off"), "md_on_m": mean("md_on")}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=5, help="synthetic scenes to generate (seeds 0..n-1)")
    ap.add_argument("--scene-dir", action="append", default=[], help="use these scenes instead")
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--work", default=None, help="where generated scenes go (default: a temp dir)")
    ap.add_argument("--json", default=None)
    ap.add_argument("--vertex-noise", type=float, default=0.0, help="Gaussian scan noise (m) on part points")
    ap.add_argument("--no-cavity", action="store_true", help="skip assembling the scenes (cavity depth check)")
    args = ap.parse_args(argv)
    dirs = [Path(d) for d in args.scene_dir]
    work = Path(args.work or tempfile.mkdtemp(prefix="ablation_refinement_"))
    if not dirs:
        from react3d_core.synthetic import generate_scene

        for s in range(args.scenes):
            d = work / f"scene_{s}"
            if not (d / "synth_meta.json").exists():
                generate_scene(d, seed=s, n_frames=args.frames)
            dirs.append(d)
    t0 = time.perf_counter()
    rows = [r for i, d in enumerate(dirs) for r in ablate_scene(d, seed=i, vertex_noise_m=args.vertex_noise)]
    res = {"summary": summarize(rows), "per_scene": {d.name: summarize([r for r in rows if r["scene"] == d.name]) for d in dirs},
           "seconds": time.perf_counter() - t0, "rows": rows}
    s = res["summary"]
    print(f"{'':14s}{'OE (deg)':>10s}{'MD (m)':>10s}   parts={s['parts']} revolute={s['revolute']}")
    print(f"{'refine off':14s}{s['oe_off_deg']:10.2f}{s['md_off_m']:10.3f}")
    print(f"{'refine on':14s}{s['oe_on_deg']:10.2f}{s['md_on_m']:10.3f}")
    for name, v in res["per_scene"].items():
        print(f"  {name}: on OE {v['oe_on_deg']:.2f} MD {v['md_on_m']:.3f} ({v['parts']} parts)")
    if not args.no_cavity:
        t1 = time.perf_counter()
        cav = [r for i, d in enumerate(dirs) for r in cavity_rows(d, work / f"assembled_{d.name}", seed=i)]
        errs = np.array([r["err"] for r in cav if r["err"] is not None])
        drawers = [r for r in cav if r["type"] == "prismatic"]
        res["cavity"] = {"objects": len(cav), "within_3cm": float((errs < 0.03).mean()) if len(errs) else float("nan"),
                         "median_err_m": float(np.median(errs)) if len(errs) else float("nan"),
                         "drawers": len(drawers), "drawer_limit_inside_cavity": all(r["upper"] <= r["cavity"] for r in drawers),
                         "sources": {k: sum(r["source"] == k for r in cav) for k in sorted({r["source"] for r in cav})},
                         "seconds": time.perf_counter() - t1, "rows": cav}
        c = res["cavity"]
        print(f"cavity depth within 3 cm: {c['within_3cm']:.1%} of {c['objects']} objects (median error {c['median_err_m']:.3f} m), "
              f"drawer limits inside cavity: {c['drawer_limit_inside_cavity']} ({c['drawers']} drawers), sources {c['sources']}")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main()
