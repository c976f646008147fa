"""``react3d synth --source urdf --up/--scale``: a Y-up asset stands up again, lengths scale, and a wrong
up axis is warned about (a Y-up asset used to be rendered lying on its side without a word)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from react3d_core.synthetic.from_urdf import UP_AXES, build_from_urdf, up_axis_votes, up_warnings
from tests.synthetic.test_urdf_sources import URDF

HALF_PI = "1.5707963267948966"
# the same cabinet exported Y-up: the fixed root joint turns the Z-up model by -90 deg about x
# (z -> y), and its offset (1, 2, 0) becomes (1, 0, -2)
URDF_YUP = URDF.replace('<origin xyz="1 2 0"/>', f'<origin xyz="1 0 -2" rpy="-{HALF_PI} 0 0"/>')


@pytest.fixture()
def files(tmp_path: Path) -> tuple[Path, Path]:
    z, y = tmp_path / "z.urdf", tmp_path / "y.urdf"
    z.write_text(URDF)
    y.write_text(URDF_YUP)
    return z, y


def _bounds(layout, key: str) -> np.ndarray:  # noqa: ANN001
    v = layout.mesh.vertices[np.unique(layout.mesh.faces[layout.face_keys == layout.key_ids[key]])]
    return np.stack([v.min(0), v.max(0)])


def test_up_rotations_are_proper_and_take_the_axis_to_z() -> None:
    for name, R in UP_AXES.items():
        axis = np.zeros(3)
        axis["xyz".index(name[-1])] = -1.0 if name.startswith("-") else 1.0
        np.testing.assert_allclose(R @ axis, [0, 0, 1], atol=1e-12)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)


def test_yup_asset_with_up_y_matches_the_zup_asset(files: tuple[Path, Path]) -> None:
    z, y = files
    ref, got = build_from_urdf(z), build_from_urdf(y, up="y")
    assert ref.extra["up_warnings"] == [] and got.extra["up_warnings"] == []
    for key in ref.key_ids:  # same geometry (bisection may split tied edges differently: compare boxes)
        np.testing.assert_allclose(_bounds(got, key), _bounds(ref, key), atol=1e-6)
    for a, b in zip(ref.parts, got.parts):
        assert a.key == b.key and a.kind == b.kind
        np.testing.assert_allclose(b.articulation.axis, a.articulation.axis, atol=1e-9)
        np.testing.assert_allclose(b.articulation.origin, a.articulation.origin, atol=1e-6)
        assert b.articulation.upper == pytest.approx(a.articulation.upper)


def test_yup_asset_read_as_zup_is_warned_about(files: tuple[Path, Path]) -> None:
    _, y = files
    lying = build_from_urdf(y)  # default --up z: the cabinet lies on its back
    slide = next(p for p in lying.parts if p.key == "slide")
    assert abs(slide.articulation.axis[2]) == pytest.approx(1.0)  # the drawer would slide vertically
    w = lying.extra["up_warnings"]
    assert w[0] == "1 of 1 prismatic joints would slide vertically"
    assert "scene y as up" in w[1] and "--up z may be wrong" in w[2]


def test_votes_by_hand() -> None:
    # a vertical hinge (+1 for z), a horizontal hinge along x (+1 x), two slides along y (-2 each)
    v = up_axis_votes(["revolute", "revolute", "prismatic", "prismatic"],
                      np.array([[0, 0, 1], [1, 0, 0], [0, -1, 0], [0, 1, 0]], float))
    np.testing.assert_allclose(v, [1, -4, 1])
    assert up_warnings(["revolute", "prismatic"], np.array([[0, 0, 1.0], [0, 1.0, 0]]), np.ones(3), "z") == []
    # tilted 30 deg off z: no longer "along" anything (cos 30 = 0.87 < 0.9), so no evidence either way
    t = np.radians(30)
    assert up_warnings(["prismatic"], np.array([[0, np.sin(t), np.cos(t)]]), np.ones(3), "z") == []


def test_scale_multiplies_lengths_and_travel(files: tuple[Path, Path]) -> None:
    z, _ = files
    one, two = build_from_urdf(z), build_from_urdf(z, scale=2.0)
    for a, b in zip(one.parts, two.parts):
        rel_a = np.asarray(a.articulation.origin) - one.extra["offset"]
        rel_b = np.asarray(b.articulation.origin) - two.extra["offset"]
        np.testing.assert_allclose(rel_b, 2.0 * rel_a, atol=1e-6)
        factor = 2.0 if a.articulation.joint_type == "prismatic" else 1.0
        assert b.articulation.upper == pytest.approx(factor * a.articulation.upper)

    np.testing.assert_allclose(np.ptp(_bounds(two, "door_hinge"), axis=0), 2.0 * np.ptp(_bounds(one, "door_hinge"), axis=0), atol=1e-6)
    with pytest.raises(ValueError, match="scale"):
        build_from_urdf(z, scale=0.0)
    with pytest.raises(ValueError, match="up axis"):
        build_from_urdf(z, up="w")


def test_synth_cli_up_and_scale(files: tuple[Path, Path], tmp_path: Path, capsys) -> None:  # noqa: ANN001
    from flows.cli import main

    _, y = files
    assert main(["synth", "--out", str(tmp_path / "p"), "--up", "y", "--frames", "2"]) == 2
    assert "apply to --source urdf only" in capsys.readouterr().err
    assert main(["synth", "--source", "urdf", "--urdf", str(y), "--out", str(tmp_path / "a"), "--frames", "2",
                 "--realism", "plain"]) == 0
    assert "warning: 1 of 1 prismatic joints would slide vertically" in " ".join(capsys.readouterr().out.split())
    assert main(["synth", "--source", "urdf", "--urdf", str(y), "--out", str(tmp_path / "b"), "--frames", "2",
                 "--realism", "plain", "--up", "y", "--scale", "1.0"]) == 0
    assert "warning" not in capsys.readouterr().out
    meta = json.loads((tmp_path / "b" / "synth_meta.json").read_text())
    assert meta["up"] == "y" and meta["scale"] == 1.0 and meta["up_warnings"] == []
