"""Fusion sub-steps on hand-made geometry with hand-computed answers."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from geometry import frames, grid, merge, two_doors  # noqa: E402

from react3d_core.config import ClipConfig, PipelineConfig
from react3d_core.data.masks import Mask2D
from react3d_core.data.mesh import TriMesh
from react3d_core.fusion import (
    clip_part,
    fill_holes,
    fuse_proposals,
    largest_component,
    lift_masks,
    point_prompts,
    ransac_plane,
    select_top_views,
    weld_labels,
)
from react3d_core.fusion.connectivity import face_components
from react3d_core.geometry import edge_adjacency
from react3d_core.fusion.graph import anchor_pairs, cooccurrence, face_graph
from react3d_core.fusion.topk import frame_ious, membership_matrix
from react3d_core.raster import Rasterizer
from react3d_core.raster.rasterizer import RasterResult


def cfg(**fusion) -> PipelineConfig:
    return PipelineConfig().with_overrides({"fusion": {"decimate_faces": None, "work_width": None, **fusion}})


# -- masks -----------------------------------------------------------------------------------
def test_fill_holes_fills_enclosed_hole_and_closes_notch():
    m = np.zeros((40, 96), bool)
    m[5:35, 10:50] = True
    m[15:20, 20:25] = False  # enclosed hole (a missed handle)
    m[0:10, 60:80] = True
    m[3:10, 69:71] = False  # 2 px notch open at the bottom
    out = fill_holes(m, close_px=0)
    assert out[15:20, 20:25].all()  # hole filled without closing
    assert not out[3:10, 69:71].any()  # notch is not a hole
    out = fill_holes(m, close_px=40)  # 4 px kernel at 96 px width
    assert out[3:9, 69:71].all()  # closed up to the mask outline
    assert not out[20:40, 0:10].any()  # nothing grows outside


def test_lift_masks_collects_visible_faces_under_eroded_mask():
    ids = np.full((10, 20), -1, np.int32)
    ids[:, :10] = 3
    ids[:, 10:] = 7
    ids[4:6, 4:6] = 9  # a 2x2 face inside the left half
    r = RasterResult("f", ids, np.ones_like(ids, np.float32))
    left = np.zeros((10, 20), bool)
    left[:, :11] = True  # bleeds one column into face 7
    c = cfg(erode_px=0)
    c = c.with_overrides({"perception": {"hole_close_px": 0}})
    lf = lift_masks(r, [Mask2D(frame_id="f", mask=left)], c)
    assert [s.tolist() for s in lf.face_sets] == [[3, 7, 9]]
    c = c.with_overrides({"fusion": {"erode_px": 96}})  # 2 px at 20 px width: the bleed column 10 goes
    lf = lift_masks(r, [Mask2D(frame_id="f", mask=left)], c)
    assert [s.tolist() for s in lf.face_sets] == [[3, 9]]
    big = np.zeros((20, 40), bool)  # a mask at twice the raster's size is resized (nearest)
    big[:, 22:] = True
    lf = lift_masks(r, [Mask2D(frame_id="f", mask=big)], cfg(erode_px=0))
    assert [s.tolist() for s in lf.face_sets] == [[7]]


# -- graph -----------------------------------------------------------------------------------
def test_cooccurrence_counts_by_hand():
    # masks {0,1,2}, {1,2}, {2,3}; adjacency (0,1), (1,2), (2,3), (0,3)
    sets = [np.array([0, 1, 2]), np.array([1, 2]), np.array([2, 3])]
    adj = np.array([[0, 1], [1, 2], [2, 3], [0, 3]])
    c = cooccurrence(sets, 4, adj, max_pairs=1, seed=0).tocsr()
    assert c[0, 1] == 1 and c[1, 2] == 2 and c[2, 3] == 1 and c[0, 3] == 0
    g = face_graph(c.tocoo(), 2)
    assert list(zip(g.row.tolist(), g.col.tolist())) == [(1, 2)]
    # without adjacency, anchors: all pairs of a 3-face mask fit in max_pairs = 6
    c = cooccurrence(sets, 4, np.zeros((0, 2), int), max_pairs=6, seed=0).tocsr()
    assert c[1, 2] == 2 and c[0, 1] == 1 and c[0, 2] == 1 and c[2, 3] == 1


def test_anchor_pairs_respect_the_cap_and_recur_across_masks():
    rng = np.random.default_rng(0)
    s = np.unique(rng.integers(0, 5000, 3000))
    pairs = anchor_pairs([s, s], 5000, max_pairs=1000, seed=1)
    assert len(pairs) <= 2 * 1000
    u, cnt = np.unique(pairs, axis=0, return_counts=True)
    assert (cnt == 2).all()  # same global anchors: each pair counted by both masks
    assert (pairs[:, 0] < pairs[:, 1]).all()


def test_edge_adjacency_and_weld():
    f = np.array([[0, 1, 2], [1, 3, 2], [4, 5, 6]])
    assert edge_adjacency(f).tolist() == [[0, 1]]
    v = np.array([[0, 0, 0], [0.001, 0, 0], [1, 0, 0]])
    lab = weld_labels(v, 0.005)
    assert lab[0] == lab[1] != lab[2]


def test_components_weld_and_attach():
    a = grid(0, 1, 0, 1, 0.0, 4, 4)
    b = grid(0, 1, 0, 1, 0.0, 4, 4)  # unwelded duplicate on top of a: welded, one component
    far = grid(5, 5.2, 0, 0.2, 0.0, 1, 1)
    handle = grid(0.4, 0.6, 0.4, 0.6, -0.01, 1, 1)  # 1 cm in front of a, no shared vertex
    m, (ia, ib, ifar, ih) = merge(a, b, far, handle)
    wf = weld_labels(m.vertices, 0.005)[m.faces]
    n, _ = face_components(wf, np.concatenate([ia, ib, ifar, ih]))
    assert n == 3
    keep = largest_component(m, wf, np.arange(m.n_faces))
    assert set(keep.tolist()) == set(np.concatenate([ia, ib]).tolist())
    keep = largest_component(m, wf, np.arange(m.n_faces), attach_m=0.02)
    assert set(keep.tolist()) == set(np.concatenate([ia, ib, ih]).tolist())


def test_components_kept_by_share():
    """A glass door's frame with its rails broken: two stiles a pane apart (0.10 x 0.60 m each, 0.06 m²) and a
    stray chip (0.05 x 0.05 m, 0.0025 m²). Shares of the 0.1225 m²: 0.49, 0.49, 0.02. At keep_share 0.2 both
    stiles stay and the chip goes; at 1 (the largest alone) one stile is left; at 0.01 all three."""
    left = grid(0.0, 0.1, 0.0, 0.6, 0.0, 2, 6)
    right = grid(0.4, 0.5, 0.0, 0.6, 0.0, 2, 6)
    chip = grid(0.9, 0.95, 0.0, 0.05, 0.0, 1, 1)
    m, (il, ir, ic) = merge(left, right, chip)
    wf = weld_labels(m.vertices, 0.005)[m.faces]
    every = np.arange(m.n_faces)
    assert m.face_areas[il].sum() == pytest.approx(0.06) and m.face_areas[ic].sum() == pytest.approx(0.0025)
    assert set(largest_component(m, wf, every, keep_share=0.2).tolist()) == set(np.concatenate([il, ir]).tolist())
    one = largest_component(m, wf, every)  # the default of the function: the largest alone (ties: the first)
    assert set(one.tolist()) == set(il.tolist())
    assert len(largest_component(m, wf, every, keep_share=0.01)) == m.n_faces
    # 0.0025 / 0.1225 = 0.0204: kept at a share just under it, not just over it
    assert len(largest_component(m, wf, every, keep_share=0.0203)) == m.n_faces
    assert len(largest_component(m, wf, every, keep_share=0.0205)) == len(il) + len(ir)
    assert PipelineConfig().fusion.keep_share == pytest.approx(0.2)


def test_pieces_kept_only_for_masks_naming_their_object():
    """keep_share holds for masks that name the object they show (a backend rendering its 3D fronts), not for a
    detector's or the oracle's (instance None): the cuts then keep the largest component alone."""
    from react3d_core.fusion.segment import pieces_config

    m = np.zeros((4, 4), bool)
    m[1:3, 1:3] = True
    named = {"f0": [], "f1": [Mask2D(frame_id="f1", label="door", score=1.0, mask=m, instance=3)]}
    unnamed = {"f1": [Mask2D(frame_id="f1", label="door", score=1.0, mask=m)]}
    c = PipelineConfig()
    assert pieces_config(named, c).fusion.keep_share == pytest.approx(0.2)
    assert pieces_config(unnamed, c).fusion.keep_share == 1.0
    assert pieces_config({}, c).fusion.keep_share == 1.0
    assert c.fusion.keep_share == pytest.approx(0.2)  # the caller's config is not changed


# -- fusion on rendered hand-made scenes ------------------------------------------------------
def _lifts(mesh: TriMesh, parts: list[np.ndarray], frs, config):
    R = Rasterizer(mesh)
    lifts, buffers, masks = [], {}, {}
    for f in frs:
        r = R.render_frame(f)
        ms = [Mask2D(frame_id=f.frame_id, mask=np.isin(r.face_ids, p)) for p in parts]
        ms = [m for m in ms if m.area]
        buffers[f.frame_id], masks[f.frame_id] = r.face_ids, ms
        lifts.append(lift_masks(r, ms, config))
    return lifts, buffers, masks


def _face_iou(a: np.ndarray, b: np.ndarray) -> float:
    return len(np.intersect1d(a, b)) / len(np.union1d(a, b))


def test_two_coplanar_doors_sharing_an_edge_are_two_parts():
    mesh, a, b = two_doors()
    c = cfg()
    lifts, _, _ = _lifts(mesh, [a, b], frames(4), c)
    props = fuse_proposals(lifts, mesh, c)
    best_a = max(_face_iou(p.face_ids, a) for p in props)
    best_b = max(_face_iou(p.face_ids, b) for p in props)
    assert best_a > 0.8 and best_b > 0.8
    assert all(_face_iou(p.face_ids, np.concatenate([a, b])) < 0.7 for p in props)  # never merged


def test_a_mask_seen_in_one_frame_yields_a_proposal_with_min_cooccurrence_1():
    mesh, a, _b = two_doors()
    c = cfg(min_cooccurrence=1)
    lifts, _, _ = _lifts(mesh, [a], frames(1), c)
    props = fuse_proposals(lifts, mesh, c)
    assert props and max(_face_iou(p.face_ids, a) for p in props) > 0.8
    c3 = cfg(min_cooccurrence=3)  # a single mask never reaches 3 co-occurrences: no graph edges
    assert fuse_proposals(lifts, mesh, c3) == []


def test_decimated_fusion_maps_back_to_scan_faces():
    mesh, a, b = two_doors()
    c = cfg().with_overrides({"fusion": {"decimate_faces": 1500}})
    lifts, _, _ = _lifts(mesh, [a, b], frames(4), c)
    props = fuse_proposals(lifts, mesh, c)
    assert max(_face_iou(p.face_ids, a) for p in props) > 0.6
    assert max(_face_iou(p.face_ids, b) for p in props) > 0.6
    assert all(p.face_ids.max() < mesh.n_faces for p in props)


# -- top-k --------------------------------------------------------------------------------------
def test_frame_iou_by_hand_is_occlusion_aware():
    ids = np.array([[0, 0, 1, 1], [0, 0, 2, -1]])  # face 1 hidden where face 2 is in front
    P = membership_matrix([np.array([0]), np.array([1, 2])], 3)
    mask = np.array([[1, 1, 1, 0], [0, 0, 0, 0]], bool)
    iou = frame_ious(ids, [mask], P)
    # proposal 0: silhouette 4 px, mask 3 px, intersection 2 -> 2 / 5; proposal 1: sil 3, inter 1 -> 1 / 5
    assert iou[0, 0] == pytest.approx(2 / 5) and iou[0, 1] == pytest.approx(1 / 5)


def test_top_views_rank_and_skip_border_masks():
    mesh, a, b = two_doors()
    c = cfg().with_overrides({"topk": {"k": 2, "border_px": 20, "min_mask_px": 100}})
    frs = frames(4, 320, 240)
    _, buffers, masks = _lifts(mesh, [a], frs, c)
    # spoil one view's mask: half of it -> lower IoU, still > 0.5 is not guaranteed: drop it entirely
    fid = frs[1].frame_id
    m = masks[fid][0].mask.copy()
    m[:, : m.shape[1] // 2] = False
    masks[fid] = [Mask2D(frame_id=fid, mask=m)]
    tv = select_top_views([a], buffers, masks, mesh.n_faces, c)[0]
    assert len(tv) == 2 and tv[0].iou >= tv[1].iou > 0.9
    assert fid not in [t.frame_id for t in tv]
    edge = np.zeros((240, 320), bool)
    edge[100:200, 0:150] = True  # touches the left border: used only when nothing else matches
    only = {fid: [Mask2D(frame_id=fid, mask=edge)]}
    assert select_top_views([a], buffers, only, mesh.n_faces, c.with_overrides({"topk": {"min_iou": 0.0}}))[0][0].frame_id == fid


def test_an_inner_view_of_a_corner_does_not_outrank_border_views_of_the_whole():
    """Proposal = faces 0..9 (unit area each). frame_a sees faces 0 and 1 in the middle of the image
    (mask IoU 128/144 = 0.89, not at the border); frame_b sees all ten, its mask touching the left border
    (IoU 1). frame_a sees 2 of the 10 faces frame_b sees: under min_view_cover 0.5 it is no better than a
    border view, so frame_b (higher IoU) leads; at 0 the inner corner view is the only one kept."""
    h, w = 64, 96
    a = np.full((h, w), 50, np.int32)
    a[28:36, 40:48], a[28:36, 48:56] = 0, 1
    mask_a = np.zeros((h, w), bool)
    mask_a[27:36, 40:56] = True
    b = np.full((h, w), 50, np.int32)
    for i in range(10):
        b[20:44, 4 * i : 4 * i + 4] = i
    buffers = {"frame_a": a, "frame_b": b}
    masks = {"frame_a": [Mask2D(frame_id="frame_a", mask=mask_a)], "frame_b": [Mask2D(frame_id="frame_b", mask=b < 10)]}
    c = cfg().with_overrides({"perception": {"hole_close_px": 0}, "topk": {"border_px": 20, "min_mask_px": 100}})
    prop = [np.arange(10)]
    tv = select_top_views(prop, buffers, masks, 100, c)[0]
    assert [t.frame_id for t in tv] == ["frame_b", "frame_a"]
    assert tv[0].iou == pytest.approx(1.0) and tv[1].iou == pytest.approx(128 / 144)
    tv = select_top_views(prop, buffers, masks, 100, c.with_overrides({"topk": {"min_view_cover": 0.0}}))[0]
    assert [t.frame_id for t in tv] == ["frame_a"]


# -- re-segmentation prompts -------------------------------------------------------------------
def test_point_prompts_inside_and_outside():
    sil = np.zeros((60, 80), bool)
    sil[10:40, 20:60] = True
    pts, lab = point_prompts(sil, n_pos=3, n_neg=4)
    pos, neg = pts[lab == 1].astype(int), pts[lab == 0].astype(int)
    assert len(pos) == 3 and sil[pos[:, 1], pos[:, 0]].all()
    assert len(neg) == 4 and not sil[neg[:, 1], neg[:, 0]].any()
    # deepest points of a 40 x 30 box: 15 px from the border, on the mid-height ridge x in [34, 45]
    assert pos[0, 1] in (24, 25) and 34 <= pos[0, 0] <= 45


# -- clipping ---------------------------------------------------------------------------------
def test_ransac_plane_by_hand():
    rng = np.random.default_rng(0)
    p = np.c_[np.full(200, 0.3), rng.uniform(0, 1, 200), rng.uniform(0, 1, 200)]  # plane x = 0.3
    n, d = ransac_plane(p, np.ones(200), ClipConfig())
    assert abs(abs(n[0]) - 1) < 1e-6 and abs(d / n[0] + 0.3) < 1e-6


def test_clip_keeps_front_slab_and_handle_drops_carcass():
    front = grid(0, 0.5, 0, 0.8, -0.02, 10, 16)  # door front at y = -0.02, camera at y = -2
    back = grid(0, 0.5, 0, 0.8, 0.0, 10, 16)  # door back 2 cm behind: kept (keep_behind 3 cm)
    back.faces = back.faces[:, ::-1].copy()  # facing +y, away from the camera
    handle = grid(0.4, 0.45, 0.3, 0.5, -0.05, 1, 2)  # 3 cm in front
    side = grid(0, 0.5, 0, 0.8, 0.0, 10, 16)
    side.vertices = side.vertices[:, [1, 0, 2]]  # carcass side: plane x = 0, y in [0, 0.5]
    top = grid(0, 0.5, 0.1, 0.5, 0.8, 5, 5)
    top.vertices = top.vertices[:, [0, 2, 1]]  # horizontal, y in [0.1, 0.5] behind the door
    mesh, (f, b, h, s, t) = merge(front, back, handle, side, top)
    keep, n, d = clip_part(mesh, np.arange(mesh.n_faces), np.array([0.25, -2.0, 0.4]), ClipConfig())
    assert np.allclose(n, [0, 1, 0], atol=1e-6) and d == pytest.approx(0.02, abs=1e-6)  # y + 0.02 = 0
    kept = set(keep.tolist())
    assert set(f.tolist()) <= kept and set(b.tolist()) <= kept and set(h.tolist()) <= kept
    cen = mesh.vertices[mesh.faces].mean(1)
    deep = np.concatenate([s, t])[cen[np.concatenate([s, t]), 1] > 0.05]
    assert len(deep) and not (set(deep.tolist()) & kept)
    off, n0, _ = clip_part(mesh, np.arange(mesh.n_faces), np.zeros(3), ClipConfig(enabled=False))
    assert n0 is None and len(off) == mesh.n_faces


def _horizontal(x0: float, x1: float, y0: float, y1: float, z: float, n: int) -> TriMesh:
    """A grid in the plane z = const facing up."""
    g = grid(x0, x1, y0, y1, z, n, n)
    g.vertices = g.vertices[:, [0, 2, 1]].copy()  # swapping y and z mirrors the -y facing grid to face up
    return g


def test_clip_keeps_a_lid_by_its_top_plane():
    # a chest freezer's lid seen from above: a 1.0 x 0.6 m top at z = 0.85 (0.6 m2), a 5 cm lip on its
    # front edge, and 12 cm of the body below the lip the mask leaked onto
    top = _horizontal(0.0, 1.0, -0.3, 0.3, 0.85, 10)
    lip = grid(0.0, 1.0, 0.80, 0.85, -0.3, 10, 5)
    body = grid(0.0, 1.0, 0.68, 0.80, -0.3, 10, 12)
    mesh, (t, lp, b) = merge(top, lip, body)
    assert (mesh.face_normals[t, 2] > 0.99).all()
    cam = np.array([0.5, -1.5, 1.6])
    keep, n, d = clip_part(mesh, np.arange(mesh.n_faces), cam, ClipConfig())
    assert np.allclose(n, [0, 0, -1]) and d == pytest.approx(0.85)  # s = 0.85 - z: > 0 below the top
    kept = set(keep.tolist())
    cz = mesh.face_centroids[:, 2]
    assert set(t.tolist()) <= kept
    assert set(lp[cz[lp] >= 0.82].tolist()) <= kept and not (set(b.tolist()) & kept)  # 3 cm below the top stay
    # the vertical rule would have kept the lip and body (the front plane y = -0.3) and dropped the top
    keep_v, n_v, _ = clip_part(mesh, np.arange(mesh.n_faces), cam, ClipConfig(lid_min_area_m2=0))
    assert abs(n_v[2]) < 1e-6 and not (set(t.tolist()) <= set(keep_v.tolist()))
    # a top of 0.1 m2 is no lid (under lid_min_area_m2 = 0.15); nor is a top above the camera
    small = merge(_horizontal(0.0, 0.5, -0.1, 0.1, 0.85, 10), lip, body)[0]
    assert abs(clip_part(small, np.arange(small.n_faces), cam, ClipConfig())[1][2]) < 1e-6
    below = clip_part(mesh, np.arange(mesh.n_faces), np.array([0.5, -1.5, 0.5]), ClipConfig())[1]
    assert abs(below[2]) < 1e-6
    # an upward area under lid_ratio times the vertical one is a front with something on top
    tall = merge(top, grid(0.0, 1.0, 0.0, 0.85, -0.3, 10, 20))[0]  # 0.85 m2 of front below the 0.6 m2 top
    assert abs(clip_part(tall, np.arange(tall.n_faces), cam, ClipConfig())[1][2]) < 1e-6


def test_a_lids_skirts_make_no_candidate_of_their_own():
    """A chest freezer's lid re-segmented to faces 0-99 (its top 0-79, its lip and side skirts 80-99) and
    clipped to the top (faces 0-79): a skirt proposal re-segmented before the lid gave candidate 0 of faces
    85-99, which all lie in the lid's re-segmented faces, so it goes; a door beside the chest (faces
    200-259) and a candidate only 10 of whose 20 faces (90-109) the lid held (0.5, not over 0.8) stay.
    A lid's own plane is horizontal: is_lid_plane says so for (0, 0, -1) and not for a front's tilted
    2 degrees, nor for no plane."""
    from react3d_core.fusion.clip import is_lid_plane
    from react3d_core.fusion.segment import drop_lid_skirts
    from react3d_core.data.parts import PartCandidate

    def cand(i: int, faces: np.ndarray) -> PartCandidate:
        return PartCandidate(candidate_id=i, face_ids=faces, vertex_ids=faces)

    skirt, lid, door, half = (cand(0, np.arange(85, 100)), cand(1, np.arange(80)), cand(2, np.arange(200, 260)),
                              cand(3, np.arange(90, 110)))
    cands = [skirt, lid, door, half]
    kept = drop_lid_skirts(cands, [(1, np.arange(100))], 0.8)
    assert [c.candidate_id for c in kept] == [1, 2, 3]
    assert len(drop_lid_skirts(cands, [], 0.8)) == 4  # no lid: nothing dropped
    c = ClipConfig()
    assert is_lid_plane(np.array([0.0, 0.0, -1.0]), c)
    assert not is_lid_plane(np.array([np.cos(np.radians(2)), 0.0, -np.sin(np.radians(2))]), c)
    assert not is_lid_plane(None, c)


def test_candidates_showing_one_perceived_object_are_one_part():
    """Four candidates on a 2 x 2 m grid mesh: three pieces of one front (their top views' masks show
    instance 4: two views of 4 and one of 9 for the third piece, so 4 by majority) and a door (instance 2).
    The pieces join into the best-scored one (score 0.7), with all their faces and vertices; the door and a
    candidate whose masks carry no instance (a per-view detector's) stay as they were."""
    from react3d_core.data.parts import PartCandidate, TopView
    from react3d_core.fusion.segment import merge_instances

    mesh = grid(0.0, 2.0, 0.0, 2.0, 0.0, 10, 10)  # 200 faces
    def view(inst):
        return TopView(frame_id="f", iou=0.9, mask=Mask2D(frame_id="f", mask=np.zeros((2, 2), bool), instance=inst))

    def cand(i, faces, score, insts):
        f = np.asarray(faces)
        return PartCandidate(candidate_id=i, score=score, face_ids=f, vertex_ids=np.unique(mesh.faces[f].ravel()),
                             top_views=[view(k) for k in insts])

    pieces = [cand(0, range(0, 20), 0.5, [4, 4]), cand(1, range(20, 50), 0.7, [4]), cand(2, range(50, 60), 0.6, [4, 4, 9])]
    door, plain = cand(3, range(100, 140), 0.8, [2]), cand(4, range(150, 160), 0.9, [None])
    out = merge_instances(pieces + [door, plain], mesh)
    assert len(out) == 3 and [c.candidate_id for c in out] == [0, 1, 2]
    joined = [c for c in out if len(c.face_ids) == 60][0]
    assert joined.score == 0.7 and np.array_equal(joined.face_ids, np.arange(60))
    assert np.array_equal(joined.vertex_ids, np.unique(mesh.faces[:60].ravel()))
    assert sorted(len(c.face_ids) for c in out) == [10, 40, 60]
