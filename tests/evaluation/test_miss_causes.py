"""Miss-cause attribution on a constructed case: hand-made GT parts and stage outputs, each with one
planted cause, attributed to that cause; and the joint causes on hand-made boxes."""

from __future__ import annotations

import numpy as np

from react3d_core.config.metrics import EvaluationConfig
from react3d_core.data.parts import OBB, Articulation
from react3d_core.metrics.miss_causes import (JOINT_CAUSES, MISS_CAUSES, PredictedJoint, ProposalTrace, StageOutputs,
                                             attribute_scene, coincident_parts, joint_causes, pool_counts)

CFG = EvaluationConfig()


def r(a: int, b: int) -> np.ndarray:
    return np.arange(a, b, dtype=np.int64)


# GT parts: 10 faces each, one planted cause per part (faces 0..199 in all)
PLANTED = {
    0: ("not_seen", r(0, 10)),
    1: ("not_masked", r(10, 20)),
    2: ("lost_in_lifting", r(20, 30)),
    3: ("merged", r(30, 40)),
    4: ("split", r(55, 65)),
    5: ("clipped", r(65, 75)),
    6: ("rejected_by_validation", r(75, 85)),
    7: ("dropped_by_dedup", r(85, 95)),
    8: ("duplicate_dropped", r(95, 105)),
    9: ("no_top_view", r(105, 115)),
    10: ("merged_in_reseg", r(115, 125)),
    11: ("resegmentation", r(125, 135)),
    12: ("lost_in_fusion", r(135, 145)),
    13: ("unobserved_geometry", r(145, 155)),
    14: ("filled_through", r(160, 170)),
    15: ("off_scan_surface", r(190, 200)),
}


def stage_outputs() -> StageOutputs:
    ok = [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13]  # parts masked and lifted in 3 views each
    masks = [PLANTED[1][1]] + [PLANTED[2][1]] * 3 + [PLANTED[k][1] for k in ok for _ in range(3)]
    glass = np.concatenate([r(160, 170), r(170, 190)])  # a door's frame and, through its empty panel, 20 faces behind
    masks += [r(160, 170)] * 3
    filled = [f for f in masks if not (len(f) and f[0] == 160)] + [glass] * 3
    masks += [np.concatenate([r(190, 192), r(170, 190)])] * 3  # on part 15 in the images, on other faces in the scan
    lifted = [PLANTED[2][1]] + [PLANTED[k][1] for k in ok for _ in range(3)] + [glass] * 3
    proposals = [
        ProposalTrace(np.concatenate([r(30, 40), r(40, 55)]), "candidate", r(30, 55), r(30, 55)),  # part 3 + 15 faces of wall
        ProposalTrace(r(55, 59), "candidate", r(55, 59), r(55, 59)),                                # part 4 in two pieces
        ProposalTrace(r(59, 63), "candidate", r(59, 63), r(59, 63)),
        ProposalTrace(r(65, 75), "candidate", r(65, 75), r(65, 68)),                                # clipping kept 3 of 10
        ProposalTrace(r(75, 85), "candidate", r(75, 85), r(75, 85)),
        ProposalTrace(r(85, 95), "candidate", r(85, 95), r(85, 95)),
        ProposalTrace(r(95, 105), "candidate", r(95, 105), r(95, 105)),
        ProposalTrace(r(105, 115), "no_views"),
        ProposalTrace(r(115, 125), "claimed"),
        ProposalTrace(r(125, 135), "candidate", r(125, 128), r(125, 128)),                         # re-seg kept 3 of 10
        ProposalTrace(r(145, 155), "candidate", r(145, 155), r(145, 155)),
    ]
    before = [p.kept_faces for p in proposals if p.status == "candidate"]
    cands = [f for f in before if not (len(f) and f[0] == 95)]  # part 8's candidate dropped as a duplicate
    validated = [not (len(f) and f[0] == 75) for f in cands]
    kept = [v and not (len(f) and f[0] == 85) for f, v in zip(cands, validated)]
    seen = np.setdiff1d(r(0, 200), r(0, 10))
    masked_2d = {pid: (1 if pid == 1 else 0 if pid == 0 else 3) for pid in PLANTED}  # from GT part-id images
    return StageOutputs(masks, filled, lifted, seen, proposals, before, cands, validated, kept, masked_2d)


def test_each_planted_miss_is_attributed_to_its_stage() -> None:
    st = stage_outputs()
    rows = [{"gt_part": pid, "iou": 0.3 if pid == 13 else 0.0, "matched": False, "pred": None} for pid in PLANTED]
    gt_faces = {pid: faces for pid, (_, faces) in PLANTED.items()}
    res = attribute_scene(gt_faces, {}, rows, [], st, CFG)
    got = {p["gt_part"]: p["causes"][0] for p in res["parts"]}
    assert got == {pid: cause for pid, (cause, _) in PLANTED.items()}
    assert set(res["counts"]["miss"]) == set(MISS_CAUSES) and set(res["counts"]["joint"]) == set(JOINT_CAUSES)
    assert res["counts"]["miss"]["other"] == 0 and sum(res["counts"]["miss"].values()) == len(PLANTED)
    merged = next(p for p in res["parts"] if p["gt_part"] == 3)
    assert merged["proposal_iou"] == 0.4 and merged["masked_views"] == 3  # 10 of the proposal's 25 faces
    # without GT images the scan's faces judge the masks: part 15's masks are then simply not on it
    st.masked_2d = None
    no_images = {p["gt_part"]: p["causes"][0] for p in attribute_scene(gt_faces, {}, rows, [], st, CFG)["parts"]}
    assert no_images[15] == "not_masked" and no_images[14] == "filled_through"
    pooled = pool_counts([res, res])
    assert pooled["miss"]["split"] == 2 and pooled["joint"]["far_edge"] == 0


def _door_obb(yaw_deg: float = 0.0) -> OBB:
    """A 0.6 (x) x 0.8 (z) x 0.02 (y) door centred at (0.3, 0.01, 0.4), turned ``yaw_deg`` about z."""
    c, s = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    return OBB(center=(0.3, 0.01, 0.4), axes=((0, 0, 1), (c, s, 0), (-s, c, 0)), extents=(0.8, 0.6, 0.02))


def _pj(jt: str, axis, origin, obb: OBB, flat: bool = True) -> PredictedJoint:  # noqa: ANN001
    a = Articulation(joint_type=jt, axis=axis, origin=origin)
    return PredictedJoint(a, a, obb, obb.R[:, 2], flat)


def test_joint_causes_on_hand_made_boxes() -> None:
    hinge = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.0, 0.01, 0.4))  # left edge
    # the prediction put the hinge at the right edge (0.6 m off) and the rule followed it: the predictor's fault
    assert joint_causes(_pj("revolute", (0, 0, 1), (0.6, 0.01, 0.4), _door_obb()), hinge, CFG) == ["wrong_hinge_side"]
    # the predicted line was nearer the left edge (0.2 m vs 0.4 m) but the refined origin is on the right: the rule's
    far = _pj("revolute", (0, 0, 1), (0.6, 0.01, 0.4), _door_obb())
    far.initial = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.2, 0.01, 0.4))
    assert joint_causes(far, hinge, CFG) == ["far_edge"]
    # the box is 10 cm too narrow on the hinge side: neither edge is on the hinge
    narrow = OBB(center=(0.35, 0.01, 0.4), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.8, 0.5, 0.02))
    assert joint_causes(_pj("revolute", (0, 0, 1), (0.1, 0.01, 0.4), narrow), hinge, CFG) == ["edge_offset"]
    drawer = Articulation(joint_type="prismatic", axis=(0, -1, 0), origin=(0.3, 0.0, 0.4))
    tilted = _door_obb(5.0)  # the box turned 5 deg: its normal is 5 deg off the pull direction
    assert joint_causes(_pj("prismatic", tilted.R[:, 2], (0.3, 0.0, 0.4), tilted), drawer, CFG) == ["obb_tilt"]
    sliding = Articulation(joint_type="prismatic", axis=(1, 0, 0), origin=(0.3, 0.0, 0.4))
    assert joint_causes(_pj("prismatic", (0, -1, 0), (0.3, 0.0, 0.4), _door_obb()), sliding, CFG) == ["sliding_not_flagged"]
    flap = Articulation(joint_type="revolute", axis=(1, 0, 0), origin=(0.3, 0.01, 0.8))
    # snapped onto the box normal (horizontal like the GT's x): the wrong side of the box
    assert joint_causes(_pj("revolute", (0, 1, 0), (0.3, 0.01, 0.8), _door_obb()), flap, CFG)[0] == "wrong_obb_axis"
    assert joint_causes(_pj("revolute", (0.1, 0.05, 1), (0.0, 0.01, 0.4), _door_obb(), flat=False), hinge, CFG) == ["not_refined"]
    assert joint_causes(_pj("prismatic", (0, -1, 0), (0.3, 0, 0.4), _door_obb()), hinge, CFG) == ["type_wrong"]
    assert joint_causes(_pj("revolute", (0, 0, 1), (0.0, 0.01, 0.4), _door_obb()), hinge, CFG) == []


def test_overlaps_weigh_faces_by_area() -> None:
    """A door front of 2 large triangles (10 m^2 each, for round numbers) and 18 small edge triangles:
    masks showing the front cover 95 % of its surface but 10 % of its faces; by area they are on it."""
    part = r(0, 20)
    area = np.where(part < 2, 10.0, 0.1 / 18 * 10)  # edges: 1 m^2 in all
    front = r(0, 2)
    st = StageOutputs(view_masks=[front] * 3, filled=[front] * 3, lifted=[front] * 3, seen=part, proposals=[],
                      before_duplicates=[], candidates=[], validated=[], kept=[])
    rows = [{"gt_part": 0, "iou": 0.0, "matched": False, "pred": None}]
    by_count = attribute_scene({0: part}, {}, rows, [], st, CFG)["parts"][0]
    assert by_count["causes"] == ["not_masked"] and by_count["masked_views"] == 0
    st.face_area = area
    by_area = attribute_scene({0: part}, {}, rows, [], st, CFG)["parts"][0]
    assert by_area["masked_views"] == 3 and by_area["lifted_cover"] == round(20 / 21, 3)
    assert by_area["causes"] == ["lost_in_fusion"]  # lifted well, but no proposal holds it


def test_mask_share_on_the_part_counts_pixels() -> None:
    """A door mask bleeding one pixel onto a wall triangle of 50 m^2: by face area it is mostly wall,
    by pixels (100 on the door, 1 on the wall) it is on the door."""
    part, wall = r(0, 2), r(2, 3)
    area = np.array([1.0, 1.0, 50.0])
    mask = np.array([0, 1, 2])
    st = StageOutputs(view_masks=[mask] * 2, filled=[mask] * 2, lifted=[mask] * 2, seen=np.concatenate([part, wall]),
                      proposals=[], before_duplicates=[], candidates=[], validated=[], kept=[], face_area=area)
    rows = [{"gt_part": 0, "iou": 0.0, "matched": False, "pred": None}]
    assert attribute_scene({0: part}, {}, rows, [], st, CFG)["parts"][0]["masked_views"] == 0
    px = [np.array([50, 50, 1])] * 2
    st.view_pixels, st.filled_pixels, st.lifted_pixels = px, px, px
    assert attribute_scene({0: part}, {}, rows, [], st, CFG)["parts"][0]["masked_views"] == 2


def test_stacked_gt_parts_are_the_data_s_fault() -> None:
    """Two wall-cabinet doors generated in one spot (a scene-synthesizer kitchen stacks cabinets) and a
    door beside them: the stacked pair is flagged, the neighbour is not; a flagged miss is not traced."""
    door = (np.array([0.0, 0.0, 1.3]), np.array([0.5, 0.02, 2.0]))
    boxes = {1: door, 2: (door[0] + [0.01, 0, 0], door[1] + [0.01, 0, 0]), 3: (door[0] + [0.5, 0, 0], door[1] + [0.5, 0, 0]),
             4: (np.array([0.0, 0.0, 0.0]), np.array([0.5, 0.0, 0.7]))}  # 4: zero-thickness front below them
    assert coincident_parts(boxes) == {1, 2}
    st = StageOutputs([], [], [], np.zeros(0, np.int64), [], [], [], [], [])
    rows = [{"gt_part": 1, "iou": 0.2, "matched": False, "pred": None}]
    res = attribute_scene({1: r(0, 10)}, {}, rows, [], st, CFG, coincident={1, 2})
    assert res["parts"][0]["causes"] == ["coincident_gt"] and res["counts"]["miss"]["coincident_gt"] == 1
