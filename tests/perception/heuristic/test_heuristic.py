"""Heuristic backend: fronts, handles and joint rules on hand-built geometry; masks vs GT on a synthetic scene."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.config import PerceptionConfig
from react3d_core.data.mesh import TriMesh
from react3d_core.perception.heuristic import make_heuristic
from react3d_core.geometry import edge_adjacency
from react3d_core.perception.heuristic.facets import planar_facets
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
    assert sorted(tuple(sorted(p)) for p in edge_adjacency(faces, chain="corner").tolist()) == [(0, 1)]


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


def _shaker_cabinet(raised: bool) -> TriMesh:
    """Two 0.498 x 0.7 m frame-and-panel doors side by side (7 cm stiles/rails, a 0.36 x 0.56 panel 8 mm
    behind the frame, or 8 mm proud of it when ``raised``), vertical handles on the inner stiles."""
    m = MeshBuilder(edge=0.05)
    m.add_box([0, 0.0, 0], [1.004, 0.6, 0.72], (200, 200, 200))                  # carcass block
    py = (-0.028, -0.001) if raised else (-0.012, -0.001)                         # panel front at -0.028 / -0.012
    for x0 in (0.002, 0.504):  # 2 mm gap between the doors
        x1 = x0 + 0.498
        for lo, hi in (([x0, -0.02, 0.01], [x0 + 0.07, -0.001, 0.71]),           # stiles and rails (front y = -0.02)
                       ([x1 - 0.07, -0.02, 0.01], [x1, -0.001, 0.71]),
                       ([x0 + 0.07, -0.02, 0.01], [x1 - 0.07, -0.001, 0.08]),
                       ([x0 + 0.07, -0.02, 0.64], [x1 - 0.07, -0.001, 0.71])):
            m.add_box(lo, hi, (150, 100, 80))
        m.add_box([x0 + 0.07, py[0], 0.08], [x1 - 0.07, py[1], 0.64], (150, 100, 80))  # panel
    m.add_box([0.46, -0.05, 0.3], [0.475, -0.02, 0.45], (30, 30, 30))            # left door handle (right stile)
    m.add_box([0.531, -0.05, 0.3], [0.546, -0.02, 0.45], (30, 30, 30))           # right door handle (left stile)
    mesh, _, _ = m.build()
    return mesh


@pytest.mark.parametrize("raised", [False, True])
def test_frame_and_panel_doors_are_whole_fronts(raised: bool) -> None:
    """A shaker door is a panel plus the stiles/rails around it: the front spans the outer 0.5 x 0.7 m
    rectangle, holds the frame's faces and hinges opposite its handle; no rail goes to the neighbour."""
    mesh = _shaker_cabinet(raised)
    facets = planar_facets(mesh)
    fronts = sorted(find_fronts(mesh, facets, _visible(mesh, facets), np.array([0.5, -2.0, 1.2])), key=lambda f: f.center[0])
    assert len(fronts) == 2
    for f, x0, hinge_x in zip(fronts, (0.002, 0.504), (0.002, 1.002)):
        assert f.w == pytest.approx(0.498, abs=0.005) and f.h == pytest.approx(0.7, abs=0.005)
        assert f.extent_v[0] == pytest.approx(0.01, abs=0.005)
        c = mesh.vertices[mesh.faces[f.faces]].mean(1)
        front_faces = c[c[:, 1] < -0.0015]
        assert front_faces[:, 0].min() < x0 + 0.07 and front_faces[:, 0].max() > x0 + 0.43  # stiles included
        assert ((front_faces[:, 0] > x0 - 0.001) & (front_faces[:, 0] < x0 + 0.499)).all()   # nothing of the neighbour
        a = f.articulation
        assert f.kind == "door" and a.origin[0] == pytest.approx(hinge_x, abs=0.006)


def test_level_carcass_around_an_inset_front_is_not_absorbed() -> None:
    """An inset door flush with the carcass face around it (dishwasher-like): the carcass stays out."""
    m = MeshBuilder(edge=0.05)
    m.add_box([0, 0.0, 0], [0.7, 0.6, 0.85], (200, 200, 200))
    m.add_box([0.0, -0.02, 0.0], [0.7, -0.001, 0.05], (200, 200, 200))     # kick plate, level with the door
    m.add_box([0.0, -0.02, 0.75], [0.7, -0.001, 0.85], (200, 200, 200))    # control strip, level
    m.add_box([0.0, -0.02, 0.053], [0.7, -0.001, 0.747], (150, 100, 80))   # the door
    m.add_box([0.2, -0.05, 0.68], [0.5, -0.02, 0.695], (30, 30, 30))       # horizontal handle, high
    mesh, _, _ = m.build()
    facets = planar_facets(mesh)
    fronts = find_fronts(mesh, facets, _visible(mesh, facets), np.array([0.35, -2.0, 1.2]))
    assert len(fronts) == 1 and fronts[0].h == pytest.approx(0.694, abs=0.005) and not fronts[0].frame_facets
    assert fronts[0].kind == "drop"
