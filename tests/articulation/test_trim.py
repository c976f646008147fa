"""Trimming a merged candidate to the predicted part: a drawer grown into the door below it, validated in a
view that shows only the drawer, is cut back to the drawer by the view that shows both."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from react3d_core.articulation.trim import trim_to_prediction
from react3d_core.camera import look_at
from react3d_core.data.frames import Frame, ImageRef, Intrinsics
from react3d_core.data.masks import ArticulationPrediction
from react3d_core.data.mesh import TriMesh
from react3d_core.data.parts import PartCandidate, TopView
from react3d_core.raster import Rasterizer

W, H = 320, 240


def grid(x0: float, x1: float, z0: float, z1: float, y: float, nx: int, nz: int) -> TriMesh:
    """An nx x nz grid of quads (2 triangles each) in the plane y = const."""
    X, Z = np.meshgrid(np.linspace(x0, x1, nx + 1), np.linspace(z0, z1, nz + 1), indexing="ij")
    v = np.stack([X.ravel(), np.full(X.size, y), Z.ravel()], 1)
    idx = np.arange(X.size).reshape(nx + 1, nz + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    return TriMesh(v, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]))


def merge(*meshes: TriMesh) -> tuple[TriMesh, list[np.ndarray]]:
    """One mesh from several, with each input's face ids in it."""
    nv = np.cumsum([0] + [m.n_vertices for m in meshes])
    nf = np.cumsum([0] + [m.n_faces for m in meshes])
    mesh = TriMesh(np.concatenate([m.vertices for m in meshes]), np.concatenate([m.faces + o for m, o in zip(meshes, nv)]))
    return mesh, [np.arange(a, b) for a, b in zip(nf[:-1], nf[1:])]


def _scene():  # noqa: ANN202
    """A drawer front (x 0..0.6, z 0.62..0.8) above a door (z 0..0.6), both 5 cm in front of a wall (y = 0),
    each with a back 2 cm behind it that no camera sees (the slab the segmentation keeps)."""
    drawer, drawer_back = grid(0.0, 0.6, 0.62, 0.8, -0.05, 12, 4), grid(0.0, 0.6, 0.62, 0.8, -0.03, 12, 4)
    door, door_back = grid(0.0, 0.6, 0.0, 0.6, -0.05, 12, 12), grid(0.0, 0.6, 0.0, 0.6, -0.03, 12, 12)
    wall = grid(-1.0, 2.0, -0.5, 1.5, 0.0, 30, 20)
    mesh, (drf, drb, dof, dob, _w) = merge(drawer, drawer_back, door, door_back, wall)
    dr, do = np.concatenate([drf, drb]), np.concatenate([dof, dob])
    intr = Intrinsics(fx=200.0, fy=200.0, cx=W / 2, cy=H / 2, width=W, height=H)

    def frame(name: str, eye: tuple[float, float, float], target: tuple[float, float, float]) -> Frame:
        return Frame(frame_id=name, rgb=ImageRef(path=Path(f"/nonexistent/{name}.jpg"), kind="jpg"), intrinsics=intr,
                     pose=look_at(np.array(eye), np.array(target)))

    # near: 0.12 m in front of the drawer, which fills its view (0.19 x 0.14 m there); far: 2 m away, both fronts
    near = frame("near", (0.3, -0.17, 0.71), (0.3, -0.05, 0.71))
    far = frame("far", (0.3, -2.0, 0.5), (0.3, 0.0, 0.4))
    return mesh, dr, do, {"near": near, "far": far}, np.concatenate([drb, dob])


def _prediction(fid: str, mask: np.ndarray) -> ArticulationPrediction:
    return ArticulationPrediction(frame_id=fid, mask=mask, joint_type="prismatic", axis_cam=(0.0, 0.0, 1.0),
                                  origin_cam=(0.0, 0.0, 1.0))


def test_a_drawer_grown_into_the_door_is_cut_back_to_the_drawer() -> None:
    mesh, dr, do, frames, backs = _scene()
    ras = Rasterizer(mesh)
    fb = {k: ras.render_frame(f).face_ids for k, f in frames.items()}
    assert not np.isin(fb["near"], do).any() and np.isin(fb["near"], dr).any()  # the near view shows no door
    assert not any(np.isin(b, backs).any() for b in fb.values())  # no view shows a back
    preds = {"near": [_prediction("near", np.isin(fb["near"], dr))],
             "far": [_prediction("far", np.isin(fb["far"], dr)), _prediction("far", np.isin(fb["far"], do))]}
    both = np.concatenate([dr, do])
    cand = PartCandidate(candidate_id=0, face_ids=both, vertex_ids=np.unique(mesh.faces[both]),
                         top_views=[TopView(frame_id="near", iou=0.9), TopView(frame_id="far", iou=0.7)])
    out = trim_to_prediction(cand, preds["near"][0], "near", preds, frames, ras, mesh)
    np.testing.assert_array_equal(np.sort(out.face_ids), np.sort(dr))
    np.testing.assert_array_equal(out.vertex_ids, np.unique(mesh.faces[dr]))
    far_mask = next(v.mask.mask for v in out.top_views if v.frame_id == "far")
    np.testing.assert_array_equal(far_mask, np.isin(fb["far"], dr))  # top-view masks of what is kept
    # the drawer alone, or with a sliver of the door under a tenth of its faces, is left as it is
    for extra in (do[:0], do[:8]):
        faces = np.concatenate([dr, extra])
        c = cand.model_copy(update={"face_ids": faces, "vertex_ids": np.unique(mesh.faces[faces])})
        assert trim_to_prediction(c, preds["near"][0], "near", preds, frames, ras, mesh) is c


def test_no_view_of_the_whole_leaves_the_candidate() -> None:
    """Where no other view shows the part's core under a prediction, nothing is known to be foreign."""
    mesh, dr, do, frames, _backs = _scene()
    ras = Rasterizer(mesh)
    fb = ras.render_frame(frames["near"]).face_ids
    preds = {"near": [_prediction("near", np.isin(fb, dr))], "far": []}
    both = np.concatenate([dr, do])
    cand = PartCandidate(candidate_id=0, face_ids=both, vertex_ids=np.unique(mesh.faces[both]),
                         top_views=[TopView(frame_id="near", iou=0.9), TopView(frame_id="far", iou=0.7)])
    assert trim_to_prediction(cand, preds["near"][0], "near", preds, frames, ras, mesh) is cand


def test_articulation_stage_trims_only_when_configured() -> None:
    """Through the stage entry point: the joint is fitted on the drawer alone with the option on, and on
    both fronts (0.8 m tall box) with it off."""
    from react3d_core.articulation import articulate_candidate
    from react3d_core.config import PipelineConfig
    from react3d_core.data.frames import SceneInput
    from react3d_core.data.masks import Mask2D

    mesh, dr, do, frames, _backs = _scene()
    ras = Rasterizer(mesh)
    fb = {k: ras.render_frame(f).face_ids for k, f in frames.items()}
    preds = {"near": [_prediction("near", np.isin(fb["near"], dr))],
             "far": [_prediction("far", np.isin(fb["far"], dr)), _prediction("far", np.isin(fb["far"], do))]}
    both = np.concatenate([dr, do])
    views = [TopView(frame_id=k, iou=0.9, mask=Mask2D(frame_id=k, mask=np.isin(fb[k], both))) for k in ("near", "far")]
    cand = PartCandidate(candidate_id=0, face_ids=both, vertex_ids=np.unique(mesh.faces[both]), top_views=views)
    scene = SceneInput(scene_id="t", root=Path("/nonexistent"), mesh_path=Path("/nonexistent/mesh.ply"),
                       frames=tuple(frames.values()), source_format="generic")
    on = articulate_candidate(scene, mesh, cand, preds, PipelineConfig(), rasterizer=ras)
    off = articulate_candidate(scene, mesh, cand, preds,
                               PipelineConfig().with_overrides({"articulation": {"trim_to_prediction": False}}), rasterizer=ras)
    assert on is not None and off is not None
    np.testing.assert_array_equal(np.sort(on.face_ids), np.sort(dr))
    np.testing.assert_array_equal(np.sort(off.face_ids), np.sort(both))
    assert abs(max(on.obb.extents) - 0.6) < 0.01 and abs(sorted(on.obb.extents)[1] - 0.18) < 0.01
    assert abs(sorted(off.obb.extents)[1] - 0.6) < 0.01 and abs(max(off.obb.extents) - 0.8) < 0.01


def test_a_view_that_sees_none_of_the_core_speaks_through_the_part_seen_in_between() -> None:
    """near sees the drawer's left part (the core) only; mid sees the drawer's middle, no door; far sees the
    drawer's right part and the door, the core hidden behind a post. far's drawer prediction covers none
    of the core, but it covers what mid added to the part, so far's door faces go."""
    drawer, door = grid(0.0, 0.6, 0.62, 0.8, -0.05, 12, 4), grid(0.0, 0.6, 0.0, 0.6, -0.05, 12, 12)
    post = grid(-0.1, 0.3, 0.55, 0.9, -0.3, 4, 4)  # 0.25 m in front of the fronts, between far and the core
    wall = grid(-1.0, 2.0, -0.5, 1.5, 0.0, 30, 20)
    mesh, (dr, do, _p, _w) = merge(drawer, door, post, wall)

    def frame(name: str, w: int, h: int, eye: tuple[float, float, float], target: tuple[float, float, float]) -> Frame:
        intr = Intrinsics(fx=200.0, fy=200.0, cx=w / 2, cy=h / 2, width=w, height=h)
        return Frame(frame_id=name, rgb=ImageRef(path=Path(f"/nonexistent/{name}.jpg"), kind="jpg"), intrinsics=intr,
                     pose=look_at(np.array(eye), np.array(target)))

    frames = {"near": frame("near", 320, 240, (0.15, -0.17, 0.71), (0.15, -0.05, 0.71)),
              "mid": frame("mid", 320, 80, (0.3, -0.25, 0.71), (0.3, -0.05, 0.71)),
              "far": frame("far", 320, 240, (0.3, -2.0, 0.4), (0.3, 0.0, 0.4))}
    ras = Rasterizer(mesh)
    fb = {k: ras.render_frame(f).face_ids for k, f in frames.items()}
    core = np.unique(fb["near"][np.isin(fb["near"], dr)])
    assert not np.isin(fb["near"], do).any() and not np.isin(fb["mid"], do).any() and np.isin(fb["far"], do).any()
    assert not np.isin(fb["far"], core).any() and np.isin(fb["far"], fb["mid"][np.isin(fb["mid"], dr)]).any()
    preds = {k: [_prediction(k, np.isin(b, dr))] + ([_prediction(k, np.isin(b, do))] if np.isin(b, do).any() else [])
             for k, b in fb.items()}
    both = np.concatenate([dr, do])
    cand = PartCandidate(candidate_id=0, face_ids=both, vertex_ids=np.unique(mesh.faces[both]),
                         top_views=[TopView(frame_id=k, iou=0.9) for k in ("near", "mid", "far")])
    out = trim_to_prediction(cand, preds["near"][0], "near", preds, frames, ras, mesh)
    assert np.isin(dr, out.face_ids).all()
    assert np.isin(do, out.face_ids).mean() < 0.1  # the door's faces behind the post follow their nearest seen face
