"""Dedup stage 6: a mask merged around a smaller front in its plane is cut back off it, so its box (and with
it the hinge, the cavity and the colliders) no longer spans the other part's front."""

from __future__ import annotations

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
