"""Cavity depth on a box cabinet, both dedup stages, carving, motion limits, whole-scene assembly."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmarks import ablation_refinement
from react3d_core.articulation.limits import revolute_limit, set_limits
from react3d_core.articulation.types import ArticulatedPart
from react3d_core.assembly import carve_background
from react3d_core.assembly.scene import _Geometry
from react3d_core.cavity import PartFrame, base_mesh, d_hit, d_mesh, estimate_cavity
from react3d_core.config import CavityConfig, DedupConfig, LimitConfig
from react3d_core.data.parts import OBB, Articulation
from react3d_core.dedup import dedup_indices, remove_duplicates
from react3d_core.dedup.remove import dedup_plan, footprint_share, grown_box
from react3d_core.geometry import overlap_counts
from react3d_core.synthetic.builder import MeshBuilder


def cabinet_mesh(depth: float = 0.5):  # noqa: ANN201
    """Open-front carcass (front plane y = 0, back board inner face at y = depth) and a door slab in front."""
    m = MeshBuilder(edge=0.05)
    t = 0.018
    m.add_box([0, 0, 0], [t, depth + t, 0.8], (200, 200, 200))
    m.add_box([0.6 - t, 0, 0], [0.6, depth + t, 0.8], (200, 200, 200))
    m.add_box([t, 0, 0], [0.6 - t, depth, t], (200, 200, 200))
    m.add_box([t, 0, 0.8 - t], [0.6 - t, depth, 0.8], (200, 200, 200))
    m.add_box([t, depth, 0], [0.6 - t, depth + t, 0.8], (200, 200, 200))
    m.add_box([0.002, -0.02, 0.002], [0.598, -0.002, 0.798], (150, 90, 60), key="door")
    mesh, keys, ids = m.build()
    return mesh, np.flatnonzero(keys == ids["door"])


def door_frame() -> PartFrame:
    return PartFrame(center=np.array([0.3, -0.011, 0.4]), u=np.array([0.0, 0.0, 1.0]), v=np.array([1.0, 0.0, 0.0]),
                     n=np.array([0.0, 1.0, 0.0]), su=0.796, sv=0.596, thickness=0.018)


def test_cavity_depth_of_a_box_cabinet() -> None:
    mesh, _ = cabinet_mesh(0.5)
    geo = _Geometry(mesh)
    pf = door_frame()
    # back face of the slab at y = -0.002; inner face of the back board at y = 0.5
    assert d_hit(pf, geo.cast, CavityConfig()) == pytest.approx(0.502, abs=1e-4)
    assert d_mesh(pf, mesh.bounds()) == pytest.approx(0.518 + 0.002, abs=1e-6)
    d, src, _ = estimate_cavity(pf, geo.cast, mesh.bounds(), None, None, CavityConfig())
    assert src == "hit" and d == pytest.approx(0.502, abs=1e-4)
    base = base_mesh(pf, d, CavityConfig())
    lo, hi = base.bounds()
    assert lo[1] == pytest.approx(-0.002 + 0.002, abs=1e-9) and hi[1] == pytest.approx(-0.002 + 0.002 + d, abs=1e-9)
    # every base face points away from its box: a closed, double-walled box (walls have thickness)
    assert base.n_faces == 5 * 12


def test_carcass_behind_a_front_off_plumb_is_level_and_clear_of_it() -> None:
    """A door 0.8 m tall estimated 1 degree off plumb (normal into the cavity tilted up by 1 degree): its
    carcass floor is level (the bottom board's 4 top corners at one height), it starts behind the front's
    back face everywhere within the outline (>= the 2 mm gap; by hand the level top edge lies
    0.4 sin 1 deg = 7.0 mm in front of the tilted back plane, so the carcass starts (2 + 7.0) / cos 1 deg
    = 9.0 mm behind the centre), and
    its back wall stays where the cavity depth puts it. A front 20 degrees off keeps its frame; a
    front within 1 degree of facing down (a flap under a worktop) is made to face exactly down."""
    from react3d_core.cavity.estimate import level_frame

    a = np.radians(1.0)
    n = np.array([0.0, np.cos(a), np.sin(a)])
    u = np.array([0.0, -np.sin(a), np.cos(a)])  # the front's height axis, tilted with it
    pf = PartFrame(center=np.array([0.3, 0.0, 0.4]), u=u, v=np.array([1.0, 0.0, 0.0]), n=n, su=0.8, sv=0.6, thickness=0.02)
    cfg = CavityConfig()
    base = base_mesh(pf, 0.5, cfg)
    w = 0.6 * cfg.wall_factor
    V = base.vertices.reshape(-1, 8, 3)  # five boxes of 8 corners: back, two sides, bottom and top boards
    boards = [b for b in V if np.ptp(b[:, 2]) == pytest.approx(w, abs=1e-9)]
    assert len(boards) == 2
    bottom = min(boards, key=lambda b: b[:, 2].min())
    top_face = bottom[np.isclose(bottom[:, 2], bottom[:, 2].max())]
    assert len(top_face) == 4 and np.ptp(top_face[:, 2]) < 1e-12
    back = pf.back
    inside = (np.abs((base.vertices - back) @ pf.v) <= 0.3 + 1e-9)
    behind = (base.vertices - back) @ n
    assert behind[inside].min() >= 0.002 - 1e-9
    level, reach = level_frame(pf, cfg.level_within_deg)
    assert reach == pytest.approx(0.4 * np.sin(a), abs=1e-12) and np.allclose(level.n, (0, 1, 0))
    assert ((base.vertices - back) @ level.n).min() == pytest.approx((0.002 + 0.4 * np.sin(a)) / np.cos(a), abs=1e-9)
    assert ((base.vertices - back) @ level.n).max() == pytest.approx(0.502, abs=1e-9)
    b = np.radians(20.0)
    steep = PartFrame(pf.center, np.array([0.0, -np.sin(b), np.cos(b)]), pf.v, np.array([0.0, np.cos(b), np.sin(b)]), 0.8, 0.6, 0.02)
    assert level_frame(steep, cfg.level_within_deg) == (steep, 0.0)
    c = np.radians(0.5)
    flap = PartFrame(pf.center, np.array([0.0, np.cos(c), np.sin(c)]), pf.v, np.array([0.0, np.sin(c), -np.cos(c)]), 0.4, 0.6, 0.02)
    assert np.allclose(level_frame(flap, cfg.level_within_deg)[0].n, (0, 0, -1))


def test_dedup_stage1_keeps_the_larger() -> None:
    a = np.arange(100)
    b = np.arange(10, 100)       # IoU 0.9 with a
    c = np.arange(200, 260)
    inter, size, _ = overlap_counts([a, b, c])
    assert inter[0, 1] == 90 and inter[0, 2] == 0 and list(size) == [100, 90, 60]
    assert dedup_indices([a, b, c], DedupConfig()) == [0, 2]


def test_dedup_stage2_removes_a_merged_part() -> None:
    left, right = np.arange(0, 50), np.arange(50, 100)
    merged = np.arange(0, 100)        # IoU 0.5 with each half: stage 1 keeps all (tau_dup = 0.5 needs >=)
    keep = dedup_indices([merged, left, right], DedupConfig(tau_dup=0.6))
    assert keep == [1, 2]              # the union of the halves covers the merged part with IoU 1.0
    # a single half does not cover it (IoU 0.5 < 0.8): stage 2 keeps the merged part, and stage 3 then
    # drops the half as a fragment of it (100 % of its vertices inside)
    assert dedup_indices([merged, left], DedupConfig(tau_dup=0.6)) == [0]


def test_dedup_stage3_removes_fragments_keeps_neighbours() -> None:
    door = np.arange(0, 500)
    panel = np.arange(100, 250)                      # 150 vertices, all inside the door: a fragment
    sliver = np.concatenate([np.arange(490, 500), np.arange(1000, 1030)])  # 10 of 40 inside (25 %)
    neighbour = np.arange(480, 900)                  # shares a 20-vertex boundary strip with the door
    keep = dedup_indices([door, panel, sliver, neighbour], DedupConfig())
    assert keep == [0, 2, 3]
    # at 0.2 the sliver (25 % inside the door, 10 / 40 inside the neighbour too) goes as well
    assert dedup_indices([door, panel, sliver, neighbour], DedupConfig(tau_contained=0.2)) == [0, 3]


def test_dedup_stage4_removes_a_sliver_inside_a_larger_parts_box() -> None:
    """A door (0.5 x 0.7 m front, 2 cm thick; 400 vertices) and a corner sliver fusion split off it
    (vertices of its own, 0.1 x 0.25 m, in the door's slab): the sliver is removed. The same sliver
    5 cm in front of the door (outside the box + 1 cm) stays; a neighbouring door of the same size
    beside it stays (not a sliver: more than a quarter of the door's size); without points or boxes
    stage 4 is skipped."""
    from react3d_core.data.parts import OBB

    rng = np.random.default_rng(0)
    door_pts = np.c_[rng.uniform(0, 0.5, 400), rng.uniform(-0.01, 0.01, 400), rng.uniform(0, 0.7, 400)]
    door_box = OBB(center=(0.25, 0.0, 0.35), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.7, 0.5, 0.02))
    sliver_pts = np.c_[rng.uniform(0.38, 0.48, 30), rng.uniform(-0.01, 0.01, 30), rng.uniform(0.02, 0.27, 30)]
    sliver_box = OBB(center=(0.43, 0.0, 0.145), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.25, 0.1, 0.02))
    nb_pts = door_pts + [0.52, 0, 0]
    nb_box = OBB(center=(0.77, 0.0, 0.35), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.7, 0.5, 0.02))
    sets = [np.arange(400), np.arange(400, 430), np.arange(430, 830)]
    cfg = DedupConfig()
    assert dedup_indices(sets, cfg, [door_pts, sliver_pts, nb_pts], [door_box, sliver_box, nb_box]) == [0, 2]
    proud = sliver_pts + [0, -0.05, 0]
    assert dedup_indices(sets, cfg, [door_pts, proud, nb_pts], [door_box, sliver_box, nb_box]) == [0, 1, 2]
    assert dedup_indices(sets, cfg) == [0, 1, 2]


def _door_part(pid: int, vids: np.ndarray, box: OBB, art: Articulation, normal=(0.0, 1.0, 0.0)) -> ArticulatedPart:
    return ArticulatedPart(candidate_id=pid, label="door", score=0.5, face_ids=vids.copy(), vertex_ids=vids, initial=art,
                           articulation=art, obb=box, front_normal=np.array(normal), thickness=0.02, flat=True)


def test_dedup_stage5_merges_a_piece_that_moves_with_a_larger_part() -> None:
    """A door (x 0..0.5, z 0..0.7, front plane y = 0, hinged on its left edge about -z) and a strip fusion
    split off its bottom-left (x 0..0.12, z -0.15..0.15, vertices of its own, the same hinge): half its
    points and 5/9 of its footprint grid lie in the door, so stages 3 and 4 keep it; stage 5 merges it into
    the door, whose box grows down to z = -0.15 (area share by hand: rows z = c + t * 0.3 with
    t = (k + 0.5) / 9 - 0.5 inside z >= -0.01 for k = 4..8, i.e. 5 of 9). The same strip hinged on the right
    edge, or as a drawer, stays; so do a door stacked above on the same hinge line and a neighbour."""
    rng = np.random.default_rng(1)
    ax = ((0, 0, 1), (1, 0, 0), (0, 1, 0))
    door_pts = np.c_[rng.uniform(0, 0.5, 400), rng.uniform(-0.01, 0.01, 400), rng.uniform(0, 0.7, 400)]
    door_box = OBB(center=(0.25, 0.0, 0.35), axes=ax, extents=(0.7, 0.5, 0.02))
    strip_pts = np.c_[rng.uniform(0, 0.12, 60), rng.uniform(-0.01, 0.01, 60), np.linspace(-0.15, 0.15, 60)]
    strip_box = OBB(center=(0.06, 0.0, 0.0), axes=ax, extents=(0.3, 0.12, 0.02))
    above_pts = door_pts + [0, 0, 0.72]
    above_box = OBB(center=(0.25, 0.0, 1.07), axes=ax, extents=(0.7, 0.5, 0.02))
    nb_pts = door_pts + [0.52, 0, 0]
    nb_box = OBB(center=(0.77, 0.0, 0.35), axes=ax, extents=(0.7, 0.5, 0.02))
    hinge = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.35), upper=1.5)
    right = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.5, -0.01, 0.35), upper=1.5)
    slide = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0.06, 0.0, 0.0), upper=0.4)
    nb_hinge = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(1.02, -0.01, 0.35), upper=1.5)
    n = np.array([0.0, 1.0, 0.0])
    sets = [np.arange(400), np.arange(400, 460), np.arange(460, 860), np.arange(860, 1260)]
    pts, boxes = [door_pts, strip_pts, above_pts, nb_pts], [door_box, strip_box, above_box, nb_box]
    cfg = DedupConfig()
    assert dedup_indices(sets, cfg, pts, boxes) == [0, 1, 2, 3]  # stages 1-4 keep the strip
    motions = [(hinge, n, False), (hinge, n, False), (hinge.model_copy(update={"origin": (0.0, -0.01, 1.07)}), n, False),
               (nb_hinge, n, False)]
    assert dedup_plan(sets, cfg, pts, boxes, motions) == ([0, 2, 3], {0: [1]})
    for other in (right, slide):
        assert dedup_indices(sets, cfg, pts, boxes, [motions[0], (other, n, False), *motions[2:]]) == [0, 1, 2, 3]
    assert dedup_indices(sets, cfg, pts, boxes, [motions[0], (hinge, n, True), *motions[2:]]) == [0, 1, 2, 3]
    assert dedup_indices(sets, cfg.model_copy(update={"motion_share": 0.6}), pts, boxes, motions) == [0, 1, 2, 3]
    assert abs(footprint_share(strip_box, door_box, 0.01, 0.03) - 5 / 9) < 1e-12
    assert footprint_share(strip_box.model_copy(update={"center": (0.06, -0.05, 0.0)}), door_box, 0.01, 0.03) == 0.0

    vertices = np.zeros((1260, 3))
    for s_, p_ in zip(sets, pts):
        vertices[s_] = p_
    parts = [_door_part(k, s_, b_, m_[0]) for k, (s_, b_, m_) in enumerate(zip(sets, boxes, motions))]
    out = remove_duplicates(parts, cfg, vertices)
    assert [p.candidate_id for p in out] == [0, 2, 3]
    door = out[0]
    assert np.array_equal(door.vertex_ids, np.arange(460)) and np.array_equal(door.face_ids, np.arange(460))
    assert np.allclose(door.obb.center, (0.25, 0.0, 0.275)) and np.allclose(door.obb.extents, (0.85, 0.5, 0.02))
    assert door.obb.axes == door_box.axes and door.articulation == hinge


def test_grown_box_keeps_extents_in_decreasing_order() -> None:
    """A 0.3 (z) x 0.25 (x) box grown sideways by a piece reaching x = 0.3 spans x -0.125..0.3 = 0.425 (centre
    0.0875), wider than tall: the axes swap to (v, -u, n)."""
    box = OBB(center=(0, 0, 0), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.3, 0.25, 0.02))
    piece = OBB(center=(0.2, 0, 0), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.1, 0.2, 0.02))
    g = grown_box(box, [piece])
    assert np.allclose(g.extents, (0.425, 0.3, 0.02)) and np.allclose(g.center, (0.0875, 0, 0))
    assert np.allclose(g.axes, ((1, 0, 0), (0, 0, -1), (0, 1, 0)))
    assert np.allclose(np.cross(g.axes[0], g.axes[1]), g.axes[2])


def test_dedup_is_bounded_on_many_overlapping_candidates() -> None:
    import time

    rng = np.random.default_rng(0)
    sets = [np.arange(s, s + int(rng.integers(50, 400))) for s in rng.integers(0, 5000, 200)]
    t0 = time.perf_counter()
    keep = dedup_indices(sets, DedupConfig())
    assert time.perf_counter() - t0 < 10.0 and 0 < len(keep) < 200


def test_carving_removes_background_inside_part_obb() -> None:
    mesh, door_faces = cabinet_mesh()
    obb = OBB(center=(0.3, -0.011, 0.4), axes=((0, 0, 1.0), (1.0, 0, 0), (0, 1.0, 0)), extents=(0.796, 0.596, 0.018))
    part = ArticulatedPart(candidate_id=0, label="door", score=1.0, face_ids=door_faces,
                           vertex_ids=np.unique(mesh.faces[door_faces]), initial=Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0, 0, 0)),
                           articulation=Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0, 0, 0)),
                           obb=obb, front_normal=np.array([0, 1.0, 0]), thickness=0.018, flat=True)
    keep = carve_background(mesh, [part], 0.005)
    assert not np.isin(door_faces, keep).any()
    inside = obb.contains(mesh.vertices, 0.005)
    assert not inside[mesh.faces[keep]].any()
    # carcass faces well behind the door survive
    assert len(keep) > 0.5 * (mesh.n_faces - len(door_faces))


def test_revolute_limit_stops_at_a_wall() -> None:
    """A door hinged 10 cm from a side wall (x = -0.1): opening towards -y swings it into the wall."""
    m = MeshBuilder(edge=0.05)
    m.add_box([-0.2, -1.0, 0], [-0.1, 0.5, 1.0], (200, 200, 200))  # wall plane x = -0.1
    wall, _, _ = m.build()
    geo = _Geometry(wall)
    own = np.zeros(wall.n_faces, bool)
    door = np.stack(np.meshgrid(np.linspace(0.02, 0.6, 30), [-0.01], np.linspace(0.1, 0.7, 10)), -1).reshape(-1, 3)
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, -0.01, 0.4))
    cfg = LimitConfig(revolute_max_deg=180, revolute_step_deg=1.0)
    q, src = revolute_limit(a, door, geo.distance_excluding(own), cfg)
    # the free edge (r = 0.6) reaches the wall plane x = -0.1 + clearance when 0.6 cos(q) = -0.09
    expect = np.pi - np.arccos(0.09 / 0.6)
    assert src == "sweep" and q == pytest.approx(expect, abs=np.radians(2.5))
    # with closest points the wall is ahead of the free edge: same stop
    q2, src2 = revolute_limit(a, door, geo.distance_excluding(own, with_points=True), cfg)
    assert src2 == "sweep" and q2 == pytest.approx(expect, abs=np.radians(2.5))
    # the axis sign is fixed so that q > 0 opens out of the cavity (+y is into the cavity)
    flipped = set_limits(a.model_copy(update={"axis": (0, 0, 1)}), door, np.array([0, 1.0, 0]), None, None, cfg)
    np.testing.assert_allclose(flipped.axis, [0, 0, -1]) and flipped.limit_source == "cap"
    drawer = set_limits(Articulation(joint_type="prismatic", axis=(0, 1, 0), origin=(0, 0, 0)), door,
                        np.array([0, 1.0, 0]), 0.5, None, cfg)
    np.testing.assert_allclose(drawer.axis, [0, -1, 0])
    assert drawer.upper == pytest.approx(0.48) and drawer.limit_source == "cavity"


def test_sweep_distance_ignores_the_parts_own_frame() -> None:
    """Front plane y = 0, cavity along +y: a jamb behind the plane is ignored, a post in the room is not."""
    m = MeshBuilder(edge=0.05)
    m.add_box([0.62, 0.0, 0], [0.7, 0.3, 1.0], (200, 200, 200), key="jamb")
    m.add_box([-0.3, -0.5, 0], [-0.2, -0.1, 1.0], (200, 200, 200), key="post")
    mesh, _, _ = m.build()
    dist = _Geometry(mesh).distance_excluding(np.zeros(mesh.n_faces, bool), np.zeros(3), np.array([0, 1.0, 0]))
    d = dist(np.array([[0.61, 0.1, 0.5], [-0.19, -0.3, 0.5]]))
    assert np.isinf(d[0])  # 1 cm from the jamb, but the jamb is behind the front plane
    assert d[1] == pytest.approx(0.01, abs=1e-6)  # 1 cm from the post (x = -0.2), which stands in the room


def test_sweep_glides_under_a_trim_beside_its_path() -> None:
    """A head trim 3 mm above the door's top edge, in the room: the door swings under it (cap), while a
    distance-only check (no closest points) stops it at once (reported blocked)."""
    m = MeshBuilder(edge=0.05)
    m.add_box([-0.2, -1.0, 0.703], [1.0, -0.02, 0.8], (200, 200, 200))  # underside z = 0.703, in the room (y < -2 cm)
    trim, _, _ = m.build()
    geo = _Geometry(trim)
    own = np.zeros(trim.n_faces, bool)
    door = np.stack(np.meshgrid(np.linspace(0.02, 0.6, 30), [0.0], np.linspace(0.1, 0.7, 10)), -1).reshape(-1, 3)
    a = Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(0.0, 0.0, 0.4))  # q > 0 swings to -y
    cfg = LimitConfig(revolute_max_deg=90, revolute_step_deg=5.0)
    assert revolute_limit(a, door, geo.distance_excluding(own, with_points=True), cfg) == (pytest.approx(np.pi / 2), "cap")
    # distance only: the top edge (2 cm from the trim's edge when closed, 3 mm under it once open) is near
    # the trim within the first 2 deg, which blocks the door below revolute_min_deg
    q, src = revolute_limit(a, door, geo.distance_excluding(own), cfg)
    assert src == "blocked" and q < np.radians(2)


@pytest.mark.slow
def test_synthetic_scene_cavities_limits_no_interpenetration(synthetic_scene, tmp_path) -> None:  # noqa: ANN001
    """Oracle parts of a synthetic kitchen through assemble_scene: cavity depth within 3 cm of the true
    interior for >= 90 % of parts, drawer limits inside the cavity, no background inside a closed part."""
    from react3d_core.assembly import assemble_scene
    from react3d_core.config import PipelineConfig
    from react3d_core.data.mesh import load_mesh

    root = synthetic_scene(seed=4, n_frames=20, kind="kitchen")
    scene, mesh, pairs = ablation_refinement.oracle_parts(root, seed=0)
    m = assemble_scene(scene, mesh, [p for p, _ in pairs], PipelineConfig(), tmp_path / "o")
    meta = json.loads((root / "synth_meta.json").read_text())
    depth_of = {p["label"]: p["interior_depth"] for p in meta["parts"] if p.get("interior_depth") is not None}
    assert len(m.objects) == len(pairs) >= 5
    gt_label = ablation_refinement.gt_labels(m.objects, [p for p, _ in pairs])
    errs = np.array([abs(o.cavity_depth - depth_of[gt_label[o.object_id]]) for o in m.objects])
    assert (errs < 0.03).mean() >= 0.9, errs
    for o in m.objects:
        assert o.articulation.lower == 0.0 and o.articulation.upper > 0
        if o.articulation.joint_type == "prismatic":
            assert o.articulation.upper <= o.cavity_depth
    bg = load_mesh(tmp_path / "o" / "meshes" / "background.ply")
    for o in m.objects:
        assert not o.obb.contains(bg.vertices, -0.005).any()  # no background vertex 5 mm deep inside a closed part


@pytest.mark.slow
def test_refinement_ablation_on_five_synthetic_scenes(synthetic_scene) -> None:  # noqa: ANN001
    """OPDMulti-like noise (7 deg, 0.2 m): refinement brings mean OE <= 1.5 deg and mean MD <= 0.05 m."""
    mod = ablation_refinement
    rows = [r for s in range(5) for r in mod.ablate_scene(synthetic_scene(seed=s, n_frames=12), seed=s)]
    res = mod.summarize(rows)
    assert res["parts"] >= 25
    assert res["oe_off_deg"] == pytest.approx(7.0)
    assert res["oe_on_deg"] <= 1.5 and res["md_on_m"] <= 0.05
    assert res["md_on_m"] < res["md_off_m"]
