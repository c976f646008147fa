"""Dedup stage 6: a mask merged around a smaller front in its plane is cut back off it, so its box (and with
it the hinge, the cavity and the colliders) no longer spans the other part's front."""

from __future__ import annotations

import dataclasses

import numpy as np

from react3d_core.articulation.types import ArticulatedPart
from react3d_core.config import DedupConfig
from react3d_core.data.parts import OBB, Articulation
from react3d_core.dedup import remove_duplicates
from react3d_core.dedup.remove import enclosing_cut

CELL = 0.02
HOLE = (0.4, 0.8, 0.1, 0.6)  # x0, x1, z0, z1 of the small front


def wall_grid(width: float = 1.0, height: float = 0.8) -> tuple[np.ndarray, np.ndarray]:
    """A front plane y = 0 meshed in 2 cm squares (two triangles each)."""
    nx, nz = int(round(width / CELL)), int(round(height / CELL))
    x, z = np.meshgrid(np.arange(nx + 1) * CELL, np.arange(nz + 1) * CELL, indexing="ij")
    v = np.c_[x.ravel(), np.zeros(x.size), z.ravel()]
    idx = np.arange(v.shape[0]).reshape(nx + 1, nz + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    return v, np.r_[np.c_[a, b, c], np.c_[a, c, d]]


def in_hole(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    c = vertices[faces].mean(1)
    x0, x1, z0, z1 = HOLE
    return (c[:, 0] > x0) & (c[:, 0] < x1) & (c[:, 2] > z0) & (c[:, 2] < z1)


BIG_BOX = OBB(center=(0.5, 0.0, 0.4), axes=((1, 0, 0), (0, 0, 1), (0, -1, 0)), extents=(1.0, 0.8, 0.0))
SMALL_BOX = OBB(center=(0.6, 0.0, 0.35), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.5, 0.4, 0.0))


def part(pid: int, faces: np.ndarray, face_ids: np.ndarray, box: OBB, art: Articulation) -> ArticulatedPart:
    return ArticulatedPart(candidate_id=pid, label="door", score=0.5, face_ids=face_ids,
                           vertex_ids=np.unique(faces[face_ids].ravel()), initial=art, articulation=art, obb=box,
                           front_normal=np.array([0.0, 1.0, 0.0]), thickness=0.0, flat=True)


def test_a_mask_merged_around_a_door_is_cut_back_to_its_largest_side() -> None:
    """The big part is the wall less the small front (x 0.4..0.8, z 0.1..0.6): a hole in it. Kept by each
    cut along its sides at the hole's edges (1 cm off), by area: x <= 0.39: 0.39 x 0.8 = 0.312; x >= 0.81:
    0.152; z <= 0.09: 0.09; z >= 0.61: 0.19. So it keeps x <= 0.39 (faces whose centroid is there: the
    last column's lower triangle, centroid 0.3867, stays, so the box ends at x = 0.40), full height."""
    v, f = wall_grid()
    hole = in_hole(v, f)
    big_f, small_f = np.flatnonzero(~hole), np.flatnonzero(hole)
    cut = enclosing_cut(BIG_BOX, big_f, SMALL_BOX, v, f, DedupConfig())
    assert cut is not None
    kept = v[f[cut.face_ids]].mean(1)
    assert kept[:, 0].max() <= 0.39 and len(cut.face_ids) == 2 * 19 * 40 + 40
    xs = (v[cut.vertex_ids] @ np.array([1.0, 0, 0]))
    assert xs.min() == 0.0 and abs(xs.max() - 0.40) < 1e-9
    assert np.allclose(cut.obb.extents, (0.8, 0.4, 0.0)) and np.allclose(cut.obb.center, (0.2, 0.0, 0.4))
    # the new box lies clear of the small front's footprint
    assert not SMALL_BOX.contains(cut.obb.corners(), -0.005).any()
    # a big part whose own surface covers the small front (a fragment or a disputed front): no cut
    assert enclosing_cut(BIG_BOX, np.arange(len(f)), SMALL_BOX, v, f, DedupConfig()) is None
    # a small front that is not inside the big box (beside it): no cut
    beside = SMALL_BOX.model_copy(update={"center": (1.3, 0.0, 0.35)})
    assert enclosing_cut(BIG_BOX, big_f, beside, v, f, DedupConfig()) is None
    # nor one in another plane (5 cm behind: a carcass's inside, not a front)
    behind = SMALL_BOX.model_copy(update={"center": (0.6, 0.05, 0.35)})
    assert enclosing_cut(BIG_BOX, big_f, behind, v, f, DedupConfig()) is None
    # a half-filled hole (every other column of the small front also in the big mask): of the big mask's
    # 0.7 m2, 0.1 lie in the small footprint, which is 0.25 of the big box: fill (0.1 / 0.7) / 0.25 = 0.571
    cols = hole & (np.floor(v[f].mean(1)[:, 0] / CELL).astype(int) % 2 == 0)
    assert enclosing_cut(BIG_BOX, np.flatnonzero(~hole | cols), SMALL_BOX, v, f, DedupConfig()) is None
    assert enclosing_cut(BIG_BOX, np.flatnonzero(~hole | cols), SMALL_BOX, v, f,
                         DedupConfig(enclosed_fill_max=0.6)) is not None

def test_dedup_cuts_the_enclosing_part_and_refines_its_hinge_with_the_scan_faces() -> None:
    v, f = wall_grid()
    hole = in_hole(v, f)
    hinge = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.02, 0.0, 0.4), upper=1.5)
    small_hinge = Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.8, 0.0, 0.35), upper=1.5)
    big = part(0, f, np.flatnonzero(~hole), BIG_BOX, hinge.model_copy(update={"origin": (0.0, 0.0, 0.4)}))
    small = part(1, f, np.flatnonzero(hole), SMALL_BOX, small_hinge)
    cfg = DedupConfig()
    kept = remove_duplicates([big, small], cfg, v)  # without the scan's faces: stages 1-5 only, both whole
    assert kept[0].obb == BIG_BOX
    out = remove_duplicates([big, small], cfg, v, f)
    assert [p.candidate_id for p in out] == [0, 1]
    assert out[1] is small
    b = out[0]
    assert np.allclose(b.obb.center, (0.2, 0.0, 0.4)) and np.allclose(b.obb.extents, (0.8, 0.4, 0.0))
    # the hinge: the edge of the new box nearer the predicted axis (x = 0.02), on the box's mid-surface
    assert b.articulation.joint_type == "revolute" and np.allclose(b.articulation.origin, (0.0, 0.0, 0.4))
    assert abs(abs(b.articulation.axis[2]) - 1) < 1e-12 and b.articulation.upper == 1.5


def test_a_mask_cut_back_onto_a_kept_front_is_removed_as_its_duplicate() -> None:
    """A mask took a door (x 0.6..1, z 0..0.5 of it) and the drawer beside it, leaving a hole where the
    drawer's own mask is (x 0.1..0.6, z 0.1..0.4). Before the cut the three are distinct (mask vs door: IoU
    0.20 / (0.35 + 0.32 - 0.20) = 0.43, 0.62 of the door inside it), so stages 1-5 keep all three. Cut back off
    the drawer it keeps its largest side, x >= 0.61 (0.39 x 0.5 against 0.09 for every other side): all of it
    over the door (IoU 0.195 / 0.32 = 0.61). Left in, it is a second body in the door's place whose front
    probe meets the door; dedup runs again on the cut parts and removes it as the door's duplicate."""
    v, f = wall_grid()
    c = v[f].mean(1)
    drawer_f = np.flatnonzero((c[:, 0] > 0.1) & (c[:, 0] < 0.6) & (c[:, 2] > 0.1) & (c[:, 2] < 0.4))
    door_f = np.flatnonzero(c[:, 0] > 0.6)
    mask_f = np.setdiff1d(np.flatnonzero(c[:, 2] < 0.5), drawer_f)
    n = np.array([0.0, 1.0, 0.0])
    mask = part(0, f, mask_f, OBB(center=(0.5, 0.0, 0.25), axes=((1, 0, 0), (0, 0, 1), (0, -1, 0)), extents=(1.0, 0.5, 0.0)),
                Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.0, 0.0, 0.25), upper=1.5))
    drawer = part(1, f, drawer_f, OBB(center=(0.35, 0.0, 0.25), axes=((1, 0, 0), (0, 0, 1), (0, -1, 0)), extents=(0.5, 0.3, 0.0)),
                  Articulation(joint_type="prismatic", axis=tuple(n), origin=(0.35, 0.0, 0.25), upper=0.4))
    door = part(2, f, door_f, OBB(center=(0.8, 0.0, 0.4), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.8, 0.4, 0.0)),
                Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(1.0, 0.0, 0.4), upper=1.5))
    cfg = DedupConfig()
    assert len(remove_duplicates([mask, drawer, door], cfg, v)) == 3  # stages 1-5 alone: all distinct
    cut = enclosing_cut(mask.obb, mask.face_ids, drawer.obb, v, f, cfg)
    assert cut is not None and v[f[cut.face_ids]].mean(1)[:, 0].min() >= 0.61
    out = remove_duplicates([mask, drawer, door], cfg, v, f)
    assert [p.candidate_id for p in out] == [1, 2]
    assert out[0] is drawer and out[1] is door


def test_a_mask_bridging_two_kept_doors_is_removed() -> None:
    """A double door: left door x 0..0.5, right door x 0.5..1 (full height, each its own mask), and a third
    mask over x 0.25..0.75, z 0..0.8 - half of each. Its vertices lie in the two doors (a column of shared
    vertices at x = 0.5 in both), half in each (>= tau_low 0.2 each, all of it >= bridge_share 0.8): a bridge,
    removed, though it is neither a fragment of either door (0.5 in each < tau_contained 0.7) nor covered by
    smaller parts (the doors are larger, stage 2 does not look at them); with tau_low 0.6 no door holds
    enough of it: kept. Over the right door's right half and
    the wall beside it instead (x 0.75..1.5 of a 1.5 m wall), one kept part holds a third of it: kept."""
    v, f = wall_grid(width=1.5)
    c = v[f].mean(1)
    n = (0.0, 1.0, 0.0)
    box = lambda x0, x1: OBB(center=((x0 + x1) / 2, 0.0, 0.4), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.8, x1 - x0, 0.0))  # noqa: E731
    hinge = lambda x, s: Articulation(joint_type="revolute", axis=(0, 0, s), origin=(x, 0.0, 0.4), upper=1.5)  # noqa: E731
    left = part(0, f, np.flatnonzero(c[:, 0] < 0.5), box(0.0, 0.5), hinge(0.0, 1))
    right = part(1, f, np.flatnonzero((c[:, 0] > 0.5) & (c[:, 0] < 1.0)), box(0.5, 1.0), hinge(1.0, -1))
    bridge = part(2, f, np.flatnonzero((c[:, 0] > 0.25) & (c[:, 0] < 0.75)), box(0.25, 0.75), hinge(0.25, 1))
    cfg = DedupConfig()
    out = remove_duplicates([left, right, bridge], cfg, v, f)
    assert [p.candidate_id for p in out] == [0, 1]
    assert [p.candidate_id for p in remove_duplicates([left, right, bridge], DedupConfig(tau_low=0.6), v, f)] == [0, 1, 2]
    beside = part(2, f, np.flatnonzero(c[:, 0] > 0.75), box(0.75, 1.5), hinge(1.5, -1))
    assert np.asarray(n) @ np.asarray(beside.front_normal) == 1.0
    assert sorted(p.candidate_id for p in remove_duplicates([left, right, beside], cfg, v, f)) == [0, 1, 2]


def test_a_scrap_off_a_doors_corner_is_merged_into_the_door_whatever_its_normal() -> None:
    """A door x 0.5..1, z 0.12..0.8 whose masks missed its bottom-left corner; that corner's own piece
    (x 0.5..0.56, z 0.08..0.16: 6 cm wide, under scrap_max_m 0.08) came out with a normal 14 degrees off and
    a hinge of its own. Stage 5's same-motion test rejects it (normals > 10 degrees apart), and of its 5 rows
    of points (z 0.08..0.16) only 3 lie in the door's box grown by 1 cm (0.6 < tau_contained 0.7): kept as a
    part of its own, it is a second body across the door's corner. As a scrap it is merged: all its points
    lie within scrap_reach_m (6 cm; the lowest 4 cm below) of the door's footprint and in its slab; the
    door's box grows down to z 0.08. The neighbouring door (x 0..0.49, full height) reaches all of it too,
    but shares only the 5 vertices on x = 0.5 with it against the door's 12 (rows z 0.12..0.16, 4 columns):
    the scrap goes to the door. The same piece 12 cm wide and 10 cm high is no scrap: kept."""
    v, f = wall_grid(width=1.0, height=0.8)
    c = v[f].mean(1)
    tilt = np.radians(14.0)
    n_off = np.array([np.sin(tilt), np.cos(tilt), 0.0])
    u = np.cross(n_off, [0.0, 0.0, 1.0])
    door_f = np.flatnonzero((c[:, 2] > 0.12) & (c[:, 0] > 0.5))
    door = part(0, f, door_f, OBB(center=(0.75, 0.0, 0.46), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)), extents=(0.68, 0.5, 0.0)),
                Articulation(joint_type="revolute", axis=(0, 0, -1), origin=(1.0, 0.0, 0.46), upper=1.5))
    left = part(2, f, np.flatnonzero(c[:, 0] < 0.49), OBB(center=(0.245, 0.0, 0.4), axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)),
                                                         extents=(0.8, 0.49, 0.0)),
                Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.0, 0.0, 0.4), upper=1.5))

    def piece(width: float, z1: float) -> ArticulatedPart:
        fs = np.flatnonzero((c[:, 0] > 0.5) & (c[:, 0] < 0.5 + width) & (c[:, 2] > 0.08) & (c[:, 2] < z1))
        box = OBB(center=(0.5 + width / 2, 0.0, (0.08 + z1) / 2), axes=((0, 0, 1), tuple(u), tuple(n_off)),
                  extents=(z1 - 0.08, width, 0.0))
        p = part(1, f, fs, box, Articulation(joint_type="revolute", axis=(0, 0, 1), origin=(0.5, 0.0, 0.12), upper=1.5))
        return dataclasses.replace(p, front_normal=n_off)

    cfg = DedupConfig()
    scrap = piece(0.06, 0.16)
    assert min(scrap.obb.extents[:2]) < cfg.scrap_max_m
    assert len(np.intersect1d(scrap.vertex_ids, door.vertex_ids)) == 12 and len(np.intersect1d(scrap.vertex_ids, left.vertex_ids)) == 5
    parts = [door, scrap, left]
    assert [p.candidate_id for p in remove_duplicates(parts, DedupConfig(scrap_max_m=0.05), v, f)] == [0, 1, 2]
    out = remove_duplicates(parts, cfg, v, f)
    assert [p.candidate_id for p in out] == [0, 2] and out[1] is left
    assert abs(out[0].obb.center[2] - out[0].obb.extents[0] / 2 - 0.08) < 1e-6  # the box reaches the corner
    assert len(out[0].face_ids) == len(np.union1d(door_f, scrap.face_ids))
    assert [p.candidate_id for p in remove_duplicates([door, piece(0.12, 0.18), left], cfg, v, f)] == [0, 1, 2]
