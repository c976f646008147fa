"""The exported-geometry check (benchmarks/bench_part_geometry.py) on the export test scene: both parts are
whole in URDF, MJCF and USD; a shrunken part mesh and a URDF joint that moves another link are caught."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from benchmarks.bench_part_geometry import check_output
from react3d_core.data.mesh import TriMesh, save_mesh


@pytest.fixture()
def copy(exported: dict[str, Path], tmp_path: Path) -> Path:
    root = exported["urdf"].parents[2]
    dst = tmp_path / "out"
    shutil.copytree(root, dst)
    return dst


def test_whole_parts_pass_in_every_format(copy: Path) -> None:
    r = check_output(copy, export=False)
    assert r["formats"] == ["urdf", "mjcf", "usd"]
    by = {p["object_id"]: p for p in r["parts"]}
    # the door sheet spans exactly its 0.48 x 0.58 box face, the drawer box its 0.58 x 0.28 face
    assert by["door"]["cover"] == pytest.approx(1.0)
    assert by["drawer"]["cover"] == pytest.approx(1.0)
    assert all(p["ok"] and p["urdf"] and p["mjcf"] and p["usd"] for p in r["parts"])


def test_sliver_and_unjointed_link_are_caught(copy: Path) -> None:
    # the drawer's mesh shrunk to its left quarter: x 0.01-0.155 of 0.01-0.59, full height
    v = np.array([[0.01, 0.48, 0.03], [0.155, 0.48, 0.03], [0.155, 0.48, 0.31], [0.01, 0.48, 0.31]])
    save_mesh(copy / "meshes" / "drawer" / "part.ply", TriMesh(v, np.array([[0, 1, 2], [0, 2, 3]])))
    urdf = copy / "export" / "urdf" / "scene.urdf"
    text = urdf.read_text()
    assert '<child link="door"/>' in text
    urdf.write_text(text.replace('<child link="door"/>', '<child link="door_base"/>', 1))
    by = {p["object_id"]: p for p in check_output(copy, export=False)["parts"]}
    assert by["drawer"]["cover"] == pytest.approx(0.25, abs=1 / 58)  # a quarter, to one 1 cm column of 58
    assert not by["drawer"]["ok"] and by["drawer"]["urdf"]
    assert by["door"]["urdf"] is False and by["door"]["mjcf"] and not by["door"]["ok"]
