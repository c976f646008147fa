"""Render a converted real scan from labelled poses: the scan mesh itself, parts tinted, labelled boxes drawn.

    python3 benchmarks/render_realscan.py RESULT [--scene ../shared/data/redkitchen]
        [--frames frame-000120,frame-000700,frame-000868] [--out-dir docs/images] [--prefix redkitchen_]

What is drawn is the scan mesh (vertex colours, flat per face, with a head-light shade so the geometry reads)
ray-cast at the pose of a labelled frame, never the dataset's photos (their licence keeps them out of the
repository). Each predicted part is rendered too and tinted where it is visible (not behind the scan surface
by more than 3 cm), with its id and joint class. The hand-drawn front boxes (mapped into the pose projection)
are drawn green when the evaluation finds the front, orange when it does not; ignore boxes grey.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from react3d_core.data.frames import Frame  # noqa: E402
from react3d_core.data.mesh import TriMesh, load_mesh  # noqa: E402
from react3d_core.metrics.box_labels import (  # noqa: E402
    BoxLabelReport, BoxLabels, PredictedPart, evaluate_box_labels, load_box_labels,
)
from react3d_core.raster import Rasterizer  # noqa: E402

DEFAULT_SCENE = (ROOT / ".." / "shared" / "data" / "redkitchen").resolve()
DEFAULT_LABELS = ROOT / "tests" / "data" / "redkitchen_fronts.json"
DEFAULT_FRAMES = ("frame-000120", "frame-000700", "frame-000868")
# RGB, no reds: the RedKitchen fronts are red and a red tint would vanish on them
PALETTE = [(0, 130, 200), (60, 180, 75), (255, 225, 25), (145, 30, 180), (70, 240, 240), (245, 130, 48),
           (210, 245, 60), (0, 128, 128), (240, 50, 230), (170, 110, 40), (0, 0, 128), (170, 255, 195)]
SHORT = {"revolute_vertical": "rev-V", "revolute_horizontal": "rev-H", "prismatic": "pris"}


def shade_scan(scan: TriMesh, frame: Frame, rast: Rasterizer) -> tuple[np.ndarray, np.ndarray]:
    """RGB render of the scan (flat face colours times a head-light Lambert term) and its z-depth."""
    r = rast.render_frame(frame)
    hit = r.face_ids >= 0
    fid = r.face_ids[hit]
    tri = scan.vertices[scan.faces[fid]]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-12
    view = tri.mean(1) - frame.c2w[:3, 3]
    view /= np.linalg.norm(view, axis=1, keepdims=True) + 1e-12
    lam = 0.55 + 0.45 * np.abs((n * view).sum(1))
    col = scan.colors[scan.faces[fid]].mean(1) * lam[:, None]
    img = np.full((*r.depth.shape, 3), 255, np.uint8)
    img[hit] = np.clip(col, 0, 255).astype(np.uint8)
    return img, r.depth


def tint_parts(img: np.ndarray, depth: np.ndarray, frame: Frame, parts: list[tuple[str, TriMesh, str]],
               depth_tol: float = 0.03, alpha: float = 0.55) -> None:
    """Blend each part's colour where it is visible and write its id and joint class at its centre (in place)."""
    for k, (pid, mesh, joint) in enumerate(parts):
        r = Rasterizer(mesh).render_frame(frame)
        vis = (r.face_ids >= 0) & ((depth <= 0) | (r.depth <= depth + depth_tol))
        if not vis.any():
            continue
        c = np.array(PALETTE[k % len(PALETTE)], float)
        img[vis] = (img[vis] * (1 - alpha) + c * alpha).astype(np.uint8)
        ys, xs = np.nonzero(vis)
        _text(img, f"{pid} {SHORT.get(joint, joint)}", (int(xs.mean()) - 40, int(ys.mean())), (255, 255, 255))


def draw_boxes(img: np.ndarray, labels: BoxLabels, frame_id: str, report: BoxLabelReport | None) -> None:
    """Labelled fronts (green found / orange missed, white without a report) and ignore boxes (grey), in place."""
    found = {f.front_id: f.found for f in report.fronts} if report else {}
    fl = labels.frames[frame_id]
    for fid, b in fl.fronts.items():
        col = (255, 255, 255) if fid not in found else ((40, 220, 40) if found[fid] else (255, 140, 0))
        p, q = (int(round(b[0])), int(round(b[1]))), (int(round(b[2])), int(round(b[3])))
        cv2.rectangle(img, p, q, col, 2)
        _text(img, fid, (p[0] + 4, p[1] + 18), col)
    for b in fl.ignore:
        cv2.rectangle(img, (int(b[0]), int(b[1])), (int(b[2]), int(b[3])), (150, 150, 150), 1)
        _text(img, "ignore", (int(b[0]) + 4, int(b[1]) + 14), (150, 150, 150))


def _text(img: np.ndarray, s: str, org: tuple[int, int], col: tuple[int, int, int]) -> None:
    for dx, dy in ((-1, 0), (1, 0), (0, -1), (0, 1)):  # a 1 px outline (a thicker stroke would widen the glyphs)
        cv2.putText(img, s, (org[0] + dx, org[1] + dy), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, s, org, cv2.FONT_HERSHEY_SIMPLEX, 0.5, col, 1, cv2.LINE_AA)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("result", type=Path, help="output folder of react3d convert (scene.json, meshes/)")
    ap.add_argument("--scene", type=Path, default=DEFAULT_SCENE)
    ap.add_argument("--labels", type=Path, default=DEFAULT_LABELS)
    ap.add_argument("--frames", default=",".join(DEFAULT_FRAMES), help="comma-separated labelled frame ids")
    ap.add_argument("--out-dir", type=Path, default=ROOT / "docs" / "images")
    ap.add_argument("--prefix", default="redkitchen_")
    args = ap.parse_args(argv)

    import json

    from react3d_core.scene_io import load_scene

    scene = load_scene(args.scene)
    labels = load_box_labels(args.labels)
    report = evaluate_box_labels(args.result, scene, labels)
    manifest = json.loads((args.result / "scene.json").read_text())
    parts = []
    for obj in manifest.get("objects", []):
        art = obj.get("articulation") or {}
        joint = PredictedPart(obj["object_id"], np.zeros((0, 3)), str(art.get("joint_type")), art.get("axis")).joint_class
        parts.append((obj["object_id"], load_mesh(args.result / obj["part_mesh"]), joint))
    scan = load_mesh(scene.mesh_path)
    rast = Rasterizer(scan)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    for fid in [f.strip() for f in args.frames.split(",") if f.strip()]:
        frame = scene.frame(fid)
        img, depth = shade_scan(scan, frame, rast)
        tint_parts(img, depth, frame, parts)
        draw_boxes(img, labels, fid, report)
        _text(img, f"{scene.scene_id} {fid}: {report.n_found}/{report.n_fronts} fronts found, "
                   f"false parts: {len(report.false_parts)}", (8, img.shape[0] - 10), (255, 255, 255))
        path = args.out_dir / f"{args.prefix}{fid}.jpg"
        cv2.imwrite(str(path), cv2.cvtColor(img, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 88])
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
