"""Heuristic backend: fronts, handles and joint rules on hand-built geometry; masks vs GT on a synthetic scene."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config import PerceptionConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic import make_heuristic
from react3d_core.perception.heuristic.facets import edge_adjacency, planar_facets
from react3d_core.perception.heuristic.fronts import find_fronts
from react3d_core.perception.interfaces import ArticulationPredictor, PointPromptSegmenter, TextPromptSegmenter
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_label_image
from react3d_core.synthetic.builder import MeshBuilder


def _cabinet() -> TriMesh:
    """Front plane y = 0 facing -y (camera at y < 0): two doors with vertical handles near their inner
    edges, a drawer above them with a horizontal handle, a carcass behind, a plain side panel."""
    m = MeshBuilder(edge=0.05)
    m.add_box([0, 0.0, 0], [1.2, 0.6, 0.8], (200, 200, 200))                     # carcass block
    m.add_box([0.002, -0.02, 0.002], [0.598, -0.001, 0.598], (150, 100, 80))     # left door
    m.add_box([0.602, -0.02, 0.002], [1.198, -0.001, 0.598], (150, 100, 80))     # right door
    m.add_box([0.002, -0.02, 0.602], [1.198, -0.001, 0.798], (150, 100, 80))     # drawer front
    m.add_box([0.53, -0.05, 0.3], [0.545, -0.02, 0.45], (30, 30, 30))            # left door handle (right edge)
    m.add_box([0.655, -0.05, 0.3], [0.67, -0.02, 0.45], (30, 30, 30))            # right door handle (left edge)
    m.add_box([0.5, -0.05, 0.69], [0.7, -0.02, 0.705], (30, 30, 30))             # drawer handle (horizontal)
    mesh, _, _ = m.build()
    return mesh


def test_edge_adjacency_hand_computed() -> None:
    faces = np.array([[0, 1, 2], [2, 1, 3], [4, 5, 6]])
    assert sorted(tuple(sorted(p)) for p in edge_adjacency(faces).tolist()) == [(0, 1)]


def _visible(mesh: TriMesh, facets) -> np.ndarray:  # noqa: ANN001
    """Facets seen (>= 20 px) from three cameras in front of the cabinet."""
    from react3d_core.camera import look_at
    from react3d_core.data.frames import Intrinsics
    from react3d_core.raster import Rasterizer

    r = Rasterizer(mesh)
    K = Intrinsics(fx=500, fy=500, cx=320, cy=240, width=640, height=480).K
    seen = np.zeros(facets.n, np.int64)
    for x in (-0.5, 0.6, 1.7):
        ids = r.render(K, look_at(np.array([x, -2.0, 1.2]), np.array([0.6, 0.0, 0.4])), 640, 480).face_ids
        seen += np.bincount(facets.labels[ids[ids >= 0]], minlength=facets.n)
    return seen >= 20


def test_fronts_handles_and_joints() -> None:
    mesh = _cabinet()
    facets = planar_facets(mesh)
    fronts = find_fronts(mesh, facets, _visible(mesh, facets), np.array([0.6, -2.0, 1.2]))
    assert len(fronts) == 3
    by = sorted(fronts, key=lambda f: (round(f.center[2], 1), f.center[0]))
    left, right, drawer = by
    assert drawer.kind == "drawer" and drawer.articulation.joint_type == "prismatic"
    np.testing.assert_allclose(drawer.articulation.axis, [0, -1, 0], atol=1e-6)  # pulled towards the room
    for door, hinge_x in ((left, 0.002), (right, 1.198)):
        a = door.articulation
        assert door.kind == "door" and a.joint_type == "revolute" and abs(a.axis[2]) == pytest.approx(1.0)
        assert a.origin[0] == pytest.approx(hinge_x, abs=1e-6)  # hinge opposite the handle
        free = np.array([1.2 - hinge_x, -0.001, 0.3])
        assert a.move(free[None], 0.3)[0][1] < -0.05  # opening swings the free edge into the room
        assert len(door.handle_facets) >= 3


def test_plain_lone_panel_is_not_a_front() -> None:
    m = MeshBuilder(edge=0.05)
    m.add_box([0, 0.0, 0], [0.6, 0.6, 0.8], (200, 200, 200))
    mesh, _, _ = m.build()
    facets = planar_facets(mesh)
    assert find_fronts(mesh, facets, _visible(mesh, facets), np.array([0.3, -2.0, 1.2])) == []


def test_backend_masks_match_gt_part_ids(synthetic_scene) -> None:  # noqa: ANN001
    scene = load_scene(synthetic_scene(seed=0, n_frames=12))
    p = make_heuristic(scene, PerceptionConfig())
    assert isinstance(p.segmenter, TextPromptSegmenter) and isinstance(p.point_segmenter, PointPromptSegmenter)
    assert isinstance(p.articulation, ArticulationPredictor)
    frames = scene.frames[::3]
    from react3d_core.scene_io.images import frame_rgb

    images = [frame_rgb(f) for f in frames]
    masks = p.segmenter.segment(frames, images, ["cabinet door"])
    preds = p.articulation.predict(frames, images)
    ious = []
    for f, ms, ps in zip(frames, masks, preds):
        gt = read_label_image(f.part_ids).astype(np.int64)
        assert len(ps) == len(ms)
        for m in ms:
            ids = gt[m.mask]
            ids = ids[ids > 0]
            best = np.bincount(ids).argmax() if len(ids) else 0
            g = gt == best
            ious.append((m.mask & g).sum() / (m.mask | g).sum())
        if ms:  # a point prompt inside the first mask returns that mask
            ys, xs = np.nonzero(ms[0].mask)
            i = len(ys) // 2
            back = p.point_segmenter.segment_points(f, images[0], np.array([[xs[i], ys[i]]]), np.array([1]))
            assert (back.mask == ms[0].mask).all()
    # handles are separate GT parts, so a front+handle mask scores a little below 1 against the front
    assert len(ious) > 10 and np.median(ious) > 0.8


def test_low_square_handleless_front_under_a_door_is_a_drawer() -> None:
    """Wardrobe column: a 0.40 x 0.41 m handle-less front under a tall door (same width) is a drawer
    (stack rule); it is taller than wide, so without its neighbour it would read as a door."""
    m = MeshBuilder(edge=0.05)
    m.add_box([0, 0.0, 0], [0.4, 0.6, 2.1], (200, 200, 200))
    m.add_box([0.0, -0.02, 0.0], [0.4, -0.001, 0.41], (150, 100, 80))    # square drawer front
    m.add_box([0.0, -0.02, 0.42], [0.4, -0.001, 2.06], (150, 100, 80))   # tall door above (1 cm gap)
    mesh, _, _ = m.build()
    facets = planar_facets(mesh)
    fronts = find_fronts(mesh, facets, _visible(mesh, facets), np.array([0.2, -2.0, 1.2]))
    kinds = sorted((round(float(f.center[2]), 1), f.kind) for f in fronts)
    assert [k for _, k in kinds] == ["drawer", "door"]
