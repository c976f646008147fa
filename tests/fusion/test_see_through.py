"""Masks that see through the front (a glass pane the scan lacks): hand-made depth images and a
hand-made glass-panel door rendered through the real rasterizer."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from geometry import frames, grid, merge  # noqa: E402

from react3d_core.config import PipelineConfig
from react3d_core.data.frames import Frame, SceneInput
from react3d_core.data.masks import Mask2D
from react3d_core.data.mesh import TriMesh
from react3d_core.fusion import lift_masks, segment_parts
from react3d_core.fusion.lift import through_pixels
from react3d_core.raster import Rasterizer

H, W = 60, 80
FX, CX, CY = 50.0, 40.0, 30.0


def plane_depth(n: np.ndarray, d: float) -> np.ndarray:
    """Depth image of the plane n . X + d = 0 (camera frame) through a pinhole (fx = fy = FX)."""
    v, u = np.mgrid[0:H, 0:W].astype(float)
    r = np.stack([(u - CX) / FX, (v - CY) / FX, np.ones_like(u)], -1)
    return (-d / (r @ n)).astype(np.float32)


def glass_door_depth() -> tuple[np.ndarray, np.ndarray, dict[str, tuple[slice, slice]]]:
    """A front tilted 17 deg about the vertical, 2 m away: mask rows 10-49, columns 15-64; inside the
    frame (rows 20-39, columns 25-54) the pane shows the inside 25 cm behind, except a handle 4 cm in
    front and a glass return 1 cm behind (within the slab)."""
    n = np.array([0.3, 0.0, -1.0]) / np.linalg.norm([0.3, 0.0, -1.0])
    z = plane_depth(n, float(n @ [0.0, 0.0, 2.0]) * -1.0)  # through (0, 0, 2)
    mask = np.zeros((H, W), bool)
    mask[10:50, 15:65] = True
    reg = {"pane": (slice(20, 40), slice(25, 55)), "handle": (slice(22, 26), slice(30, 34)),
           "glass": (slice(35, 38), slice(45, 50))}
    front = z.copy()
    z[reg["pane"]] = front[reg["pane"]] + 0.25
    z[reg["handle"]] = front[reg["handle"]] - 0.04
    z[reg["glass"]] = front[reg["glass"]] + 0.01
    return z, mask, reg


def test_through_pixels_by_hand_on_a_tilted_front():
    z, mask, reg = glass_door_depth()
    out = through_pixels(mask, z, band_px=3, behind_m=0.03)
    want = np.zeros((H, W), bool)
    want[reg["pane"]] = True
    want[reg["handle"]] = False  # in front of the plane: a handle stays
    want[reg["glass"]] = False  # 1 cm behind: within the slab (a pane return)
    assert np.array_equal(out, want)
    z0 = z.copy()
    z0[30, 40] = 0.0  # no surface: never through
    assert not through_pixels(mask, z0, 3, 0.03)[30, 40]


def test_a_front_cut_off_by_the_image_border_has_no_outline_there():
    z, mask, reg = glass_door_depth()
    z, mask = z[20:], mask[20:]  # the image starts at the pane's top: the mask runs into the border there
    want = np.zeros(mask.shape, bool)
    want[0:20, 25:55] = True
    want[2:6, 30:34] = False  # the handle
    want[15:18, 45:50] = False  # the pane return
    assert np.array_equal(through_pixels(mask, z, 3, 0.03), want)
    # a crop whose top is not the image's border: the top rows are outline (on the pane), never through
    inner = through_pixels(mask, z, 3, 0.03, image_sides=(False, True, True, True))
    assert not inner[0:3].any() and np.array_equal(inner[3:], want[3:])


def test_through_pixels_ignore_bleed_in_the_band_and_leave_solid_fronts_alone():
    z, mask, reg = glass_door_depth()
    bled = z.copy()
    bled[10:50, 15] += 0.5  # the mask's left column bleeds onto the wall 50 cm behind
    want = through_pixels(mask, z, 3, 0.03)
    got = through_pixels(mask, bled, 3, 0.03)
    assert np.array_equal(got[:, 16:], want[:, 16:]) and got.sum() == want.sum()
    solid = z.copy()
    solid[reg["pane"]] -= 0.25  # the pane filled in: a solid door
    assert not through_pixels(mask, solid, 3, 0.03).any()
    assert not through_pixels(mask, z, 0, 0.03).any()  # band 0: off
    tiny = np.zeros((H, W), bool)
    tiny[28:31, 38:41] = True  # 9 px: too few band pixels to fit a plane
    assert not through_pixels(tiny, z, 3, 0.03).any()


def test_no_plane_from_an_outline_that_is_a_line_or_two_planes_and_no_slivers():
    v, u = np.mgrid[0:H, 0:W].astype(float)
    z = (1.2 + 0.01 * v + 0.004 * u).astype(np.float32)  # a plane seen at a slant
    mask = np.zeros((H, W), bool)
    mask[:, 20:] = True  # cut off by the image at the top, bottom and right: one edge of outline
    deep = z.copy()
    deep[10:50, 40:70] += 0.3
    assert not through_pixels(mask, deep, 3, 0.03).any()
    box = np.zeros((H, W), bool)
    box[10:50, 15:65] = True
    two = z.copy()
    two[:, 40:] += 0.2  # the right half of the outline lies on another surface 20 cm back
    assert not through_pixels(box, two, 3, 0.03).any()
    sliver = z.copy()
    sliver[15:45, 39:41] += 0.1  # a 2 px strip off the plane (faces reaching a few cm deep): no panel
    assert not through_pixels(box, sliver, 3, 0.03).any()
    sliver[15:45, 30:38] += 0.1  # an 8 px wide region is a panel
    got = through_pixels(box, sliver, 3, 0.03)
    assert got[15:45, 30:38].all() and got.sum() == 30 * 8


# -- a glass-panel door in front of a cabinet's inside, rendered ------------------------------
RING = 0.08  # frame width (m)


def glass_door_scene() -> tuple[TriMesh, np.ndarray, np.ndarray, TriMesh]:
    """A 0.5 x 0.8 m frame (8 cm bars) at y = -0.05 whose pane the scan lacks, the cabinet's back
    wall 30 cm behind and a box of books 12 cm behind; also the door with its pane (for masks)."""
    bars = [grid(0.0, 0.5, 0.0, RING, -0.05, 10, 2), grid(0.0, 0.5, 0.8 - RING, 0.8, -0.05, 10, 2),
            grid(0.0, RING, RING, 0.8 - RING, -0.05, 2, 12), grid(0.5 - RING, 0.5, RING, 0.8 - RING, -0.05, 2, 12)]
    back = grid(-0.2, 0.7, -0.2, 1.0, 0.3, 18, 24)
    books = grid(0.15, 0.35, 0.2, 0.45, 0.07, 4, 5)
    mesh, ids = merge(*bars, back, books)
    ring = np.concatenate(ids[:4])
    behind = np.concatenate(ids[4:])
    panel, _ = merge(grid(0.0, 0.5, 0.0, 0.8, -0.05, 10, 16), back)
    return mesh, ring, behind, panel


def door_masks(panel: TriMesh, frs: list[Frame]) -> dict[str, list[Mask2D]]:
    """The whole door (frame and pane) per frame, as a model or the GT part-id images see it."""
    R = Rasterizer(panel)
    out = {}
    for f in frs:
        ids = R.render_frame(f).face_ids
        out[f.frame_id] = [Mask2D(frame_id=f.frame_id, mask=(ids >= 0) & (ids < 10 * 16 * 2))]
    return out


def cfg(**fusion) -> PipelineConfig:
    return PipelineConfig().with_overrides({"fusion": {"decimate_faces": None, "work_width": None, **fusion}})


def test_lifting_a_glass_door_keeps_its_frame_and_leaves_what_lies_behind():
    mesh, ring, behind, panel = glass_door_scene()
    frs = frames(4, 320, 240, target=(0.25, 0.0, 0.4))
    masks = door_masks(panel, frs)
    R = Rasterizer(mesh)
    lifted, lifted_off = [], []
    for f in frs:
        r = R.render_frame(f)
        lifted.append(np.concatenate(lift_masks(r, masks[f.frame_id], cfg()).face_sets))
        lifted_off.append(np.concatenate(lift_masks(r, masks[f.frame_id], cfg(through_band_px=0)).face_sets))
    got, off = np.unique(np.concatenate(lifted)), np.unique(np.concatenate(lifted_off))
    assert not np.isin(got, behind).any()
    assert np.isin(ring, got).mean() > 0.8
    assert np.isin(off, behind).sum() > 50  # without the test the books and back wall come along


class PanelSegmenter:
    """Point prompts answered with the door's whole mask in that frame (what SAM or the oracle give)."""

    def __init__(self, masks: dict[str, list[Mask2D]]) -> None:
        self.masks = masks

    def segment_points(self, frame: Frame, image: np.ndarray, points: np.ndarray, labels: np.ndarray) -> Mask2D:
        return self.masks[frame.frame_id][0]


def test_segmenting_a_glass_door_gives_its_frame_as_one_part():
    mesh, ring, behind, panel = glass_door_scene()
    frs = frames(5, 320, 240, target=(0.25, 0.0, 0.4))
    masks = door_masks(panel, frs)
    scene = SceneInput(scene_id="glass", root=Path("/nonexistent"), mesh_path=Path("/nonexistent/m.ply"), frames=tuple(frs),
                       source_format="generic")
    cands = segment_parts(scene, mesh, masks, PanelSegmenter(masks), cfg())
    assert len(cands) == 1
    faces = cands[0].face_ids
    assert not np.isin(faces, behind).any()
    assert np.isin(ring, faces).mean() > 0.95
