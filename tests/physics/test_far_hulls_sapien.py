"""Convex collision files are written around their own centre, which PhysX needs.

Traced on a generated kitchen: a flap blew up in SAPIEN only. At rest, a 1 cm piece of the flap and a
6 mm background sliver cut back beside it stood 7 mm apart, yet PhysX reported contacts 1.5 cm deep.
Both hulls' vertices lay metres from their files' origin (link-local coordinates); PhysX cooks and
collides a convex mesh in its file's coordinates and loses the small hull there. The exporter now
centres each collision file on the piece and moves it into place with the URDF origin.

The test writes the traced pair through the exporter (``write_link_assets`` + ``urdf_text``) at many
placements, every one with the hulls at least 3 mm apart, loads the URDF in SAPIEN and steps once:
no contact may be deeper than 1 mm. The same files written the old way (vertices link-local, origin 0)
are the control that shows the placements reach PhysX's failure; where a SAPIEN release no longer
fails on them, the test is skipped rather than passing without proving anything.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("sapien")

from react3d_core.config.export import ExportConfig  # noqa: E402
from react3d_core.data.parts import Articulation  # noqa: E402
from react3d_core.export.assets import write_link_assets  # noqa: E402
from react3d_core.export.collision import ConvexPiece  # noqa: E402
from react3d_core.export.inertia import Inertial  # noqa: E402
from react3d_core.export.model import Joint, Link, SceneModel  # noqa: E402
from react3d_core.export.urdf import urdf_text  # noqa: E402
from react3d_core.physics.sapien_sim import SapienSim  # noqa: E402

# the traced pair, world coordinates (m): a corner piece of the flap and the background sliver behind it
FLAP_PIECE = np.array([[1.6852, 4.1721, 0.8235], [1.6851, 4.1771, 0.8235], [1.6874, 4.1771, 0.8191], [1.6875, 4.1721, 0.8191],
                       [1.6957, 4.1774, 0.8235], [1.6934, 4.1773, 0.8279], [1.6959, 4.1724, 0.8235], [1.6935, 4.1723, 0.8279]])
SLIVER = np.array([[1.6901, 4.1856, 0.81], [1.6841, 4.1856, 0.81], [1.6838, 4.1885, 0.8298], [1.6899, 4.1885, 0.8298],
                   [1.6838, 4.1842, 0.8304], [1.6899, 4.1843, 0.8304], [1.6901, 4.1843, 0.8102], [1.6856, 4.1842, 0.8102],
                   [1.6841, 4.1842, 0.8102]])
HINGE = np.array([1.33, 4.176, 0.275])  # the flap's joint: its link frame, 0.55 m from the piece


def _piece(points: np.ndarray) -> ConvexPiece:
    import trimesh

    hull = trimesh.Trimesh(points, process=False).convex_hull
    return ConvexPiece(np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int64), "patch")


def _model(shift: np.ndarray) -> SceneModel:
    flap = _piece(FLAP_PIECE + shift)
    inertial = Inertial(0.5, FLAP_PIECE.mean(0) + shift, np.full(3, 1e-3), np.eye(3))
    links = [Link("background", np.zeros(3), patches=[_piece(SLIVER)], inertial=Inertial(0.01, SLIVER.mean(0), np.full(3, 1e-3), np.eye(3))),
             # as exported: the part hangs from its carcass link, so it collides with the background (not its parent)
             Link("flap_base", HINGE + shift, inertial=inertial, object_id="flap", role="base"),
             Link("flap", HINGE + shift, collisions=[flap], inertial=inertial, object_id="flap", role="part")]
    art = Articulation(joint_type="prismatic", axis=(0.0, -1.0, 0.0), origin=tuple(map(float, HINGE + shift)), lower=0.0, upper=0.1)
    return SceneModel("far_hulls", links, [Joint("flap_joint", "flap", "flap_base", "flap", art)])


def _write(model: SceneModel, folder: Path, centred: bool) -> Path:
    files = write_link_assets(model, folder, ExportConfig(), glb=False)
    text = urdf_text(model, {k: v.prefixed("") for k, v in files.items()}, ExportConfig())
    if not centred:  # the former layout: vertices in link-local coordinates, every mesh collision at the link origin
        for link in model.links:
            for piece, rel in zip(link.collisions + [p for p in link.patches if p.box is None],
                                  files[link.name].collisions + files[link.name].patches, strict=True):
                obj = folder / rel
                lines = obj.read_text().splitlines()
                moved = [f"v {' '.join(f'{c:.9g}' for c in np.array(ln.split()[1:], float) + piece.centre - link.frame)}"
                         if ln.startswith("v ") else ln for ln in lines]
                obj.write_text("\n".join(moved) + "\n")
        text = re.sub(r'<origin xyz="[^"]*" rpy="0 0 0"/>(\s*<geometry><mesh)', r'<origin xyz="0 0 0" rpy="0 0 0"/>\1', text)
    urdf = folder / "scene.urdf"
    urdf.write_text(text)
    return urdf


def _deepest(urdf: Path) -> float:
    sim = SapienSim(urdf, 1 / 240)
    try:
        sim.reset(np.zeros(len(sim.joints)))
        sim.scene.step()
        # every point PhysX generates (within its contact offset), not only touching ones
        return min((float(p.separation) for c in sim.scene.get_contacts() for p in c.points), default=np.inf)
    finally:
        sim.close()


def test_small_hulls_far_from_their_link_origin_collide_exactly_in_sapien(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    # the sliver lies 6.8 mm beyond the flap piece along +y; moving the piece only away in y keeps >= 3 mm between them
    shifts = np.column_stack([rng.uniform(-0.01, 0.01, 30), rng.uniform(-0.008, 0.0035, 30), rng.uniform(-0.01, 0.01, 30)])
    centred, former = [], []
    for k, s in enumerate(shifts):
        model = _model(s)
        for layout, out in ((True, centred), (False, former)):
            folder = tmp_path / f"{k}_{int(layout)}"
            folder.mkdir()
            out.append(_deepest(_write(model, folder, layout)))
    centred, former = np.array(centred), np.array(former)
    assert np.isfinite(centred).all(), "every placement must bring the pair within PhysX's contact distance"
    if not (former < -1e-3).any():
        pytest.skip("this SAPIEN collides far-from-origin hulls exactly: the failure the exporter avoids does not occur")
    assert (centred > -1e-3).all(), f"deepest contacts {np.sort(centred)[:3]} m between hulls >= 3 mm apart"
