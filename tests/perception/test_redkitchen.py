"""Real scan acceptance: 7-Scenes RedKitchen, scored against hand-drawn front boxes.

The scan lives outside the repository (../shared/data/redkitchen, non-commercial licence, never copied in);
the tests skip when it is absent. ``tests/data/redkitchen_fronts.json`` holds 2D boxes of the 9 clearly
visible fronts (3 doors on the left leg, 4 under the sink, 2 wide fronts on the red wall-hung unit) in
7 colour frames; ``react3d_core.metrics.box_labels`` projects every predicted part into those frames
(occlusion-aware) and matches parts to fronts one-to-one on mean box IoU.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from react3d_core.metrics.box_labels import (
    PredictedPart, evaluate_box_labels, load_box_labels, match_boxes, part_boxes,
)

REPO = Path(__file__).resolve().parents[2]
SCENE = (REPO / ".." / "shared" / "data" / "redkitchen").resolve()
LABELS = REPO / "tests" / "data" / "redkitchen_fronts.json"
DOORS = ("L1", "L2", "L3", "B1", "B2", "B3", "B4")  # full-height doors: vertical hinges
WIDE = ("R1", "R2")  # wide short fronts: drawers or top-hinged flaps

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not (SCENE / "transforms.json").is_file(), reason=f"RedKitchen scan not found at {SCENE}")]


@pytest.fixture(scope="module")
def scene():
    from react3d_core.scene_io import load_scene

    return load_scene(SCENE)


def test_redkitchen_fronts_found_as_separate_parts(tmp_path, scene, prefect_server):
    """>= 7 of 9 fronts, each its own part covering one front, plausible joints, <= 1 false part.

    With the default frames (the keyframe selection keeps 119 of 250), what a user gets. The heuristic's
    RedKitchen result depends on the view set: 7-Scenes' colour frames are each misregistered by their own
    amount, so the fused orthophotos differ (every 3rd, 4th and 5th frame: docs/results.md)."""
    out = tmp_path / "out"
    env = dict(os.environ, REACT3D_CACHE=str(tmp_path / "cache"),  # a cold cache: the run is the pipeline's
               PREFECT_HOME=str(prefect_server.home))  # the run's Prefect server, not one in the user's home
    env.pop("PREFECT_API_URL", None)
    proc = subprocess.run([sys.executable, "-m", "flows.cli", "convert", str(SCENE), "--out", str(out)],
                          cwd=REPO, env=env, capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    report = evaluate_box_labels(out, scene, LABELS)
    summary = "\n".join(f"{f.front_id}: part={f.part} iou={f.iou:.2f} other={f.other_iou:.2f} joint={f.joint_class}"
                        for f in report.fronts) + f"\nfalse parts: {report.false_parts}"
    found = [f for f in report.fronts if f.found]
    assert len(found) >= 7, f"{len(found)} of 9 fronts found\n{summary}"
    for f in found:
        assert f.other_iou < report.iou_threshold, f"part {f.part} also covers another front\n{summary}"
        if f.front_id in DOORS:
            assert f.joint_class == "revolute_vertical", summary
        elif f.front_id in WIDE:
            assert f.joint_class in ("prismatic", "revolute_horizontal"), summary
    assert len(report.false_parts) <= 1, summary


def _scan_points_in_box(rast, scan, frame, box: tuple[float, float, float, float], shrink: int = 4) -> np.ndarray:
    """Scan vertices seen inside a box, reduced to their dominant plane (the front, not the floor or a chair)."""
    import open3d as o3d

    x0, y0, x1, y1 = (int(round(v)) for v in box)
    ids = rast.render_frame(frame).face_ids[y0 + shrink:y1 - shrink, x0 + shrink:x1 - shrink].ravel()
    pts = scan.vertices[np.unique(scan.faces[ids[ids >= 0]].ravel())]
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    _, inliers = pc.segment_plane(0.02, 3, 1000)
    return pts[np.asarray(inliers)]


def test_labels_admit_a_perfect_answer(scene):
    """The stick can be passed: for every front, the scan vertices whose visible projection lies inside its box
    in all of its labelled frames form a part that the evaluation finds (guards against inconsistent boxes or
    a wrong colour-to-pose registration), and such a part set gives 9 of 9 with no false part."""
    from react3d_core.data.mesh import load_mesh
    from react3d_core.metrics.box_labels import project_visible
    from react3d_core.raster import Rasterizer

    labels = load_box_labels(LABELS)
    scan = load_mesh(scene.mesh_path)
    rast = Rasterizer(scan)
    depth = {fid: rast.render_frame(scene.frame(fid)).depth for fid in labels.frames}
    parts = []
    for front in labels.front_ids:
        frames = [fid for fid, fl in labels.frames.items() if front in fl.fronts]
        pts = np.unique(np.concatenate([_scan_points_in_box(rast, scan, scene.frame(fid), labels.frames[fid].fronts[front])
                                        for fid in frames]), axis=0)
        keep = np.ones(len(pts), bool)
        for fid in frames:  # drop points seen outside the box (3 px slack) in any labelled frame
            x0, y0, x1, y1 = labels.frames[fid].fronts[front]
            uv, seen = project_visible(pts, scene.frame(fid), depth[fid])
            inside = (uv[:, 0] >= x0 - 3) & (uv[:, 0] <= x1 + 3) & (uv[:, 1] >= y0 - 3) & (uv[:, 1] <= y1 + 3)
            keep &= ~seen | inside
        parts.append(PredictedPart(f"ideal_{front}", pts[keep], "revolute", (0.0, 0.0, 1.0)))
    report = match_boxes(part_boxes(parts, scene, labels, scan=scan), labels)
    assert report.n_found == 9, [(f.front_id, round(f.iou, 2)) for f in report.fronts]
    assert all(f.part == f"ideal_{f.front_id}" and f.iou >= 0.75 for f in report.fronts)
    assert report.false_parts == []
