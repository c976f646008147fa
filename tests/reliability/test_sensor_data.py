"""Bad sensor data is an error naming the file (rc 2), never a silently wrong scene
(the scan is checked before anything starts: the CLI runs in this process)."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np

from react3d_core.data.mesh import TriMesh, load_mesh, save_mesh
from react3d_core.scene_io import load_scene
from react3d_core.scene_io.images import read_depth

from .conftest import FAST, first_line, run_cli_here


def _copy(scan: Path, tmp_path: Path) -> Path:
    s = tmp_path / "S"
    shutil.copytree(scan, s)
    return s


def _bad_input(r, path: Path, words: str) -> None:  # noqa: ANN001
    assert r.returncode == 2, (r.returncode, r.stdout[-1500:], r.stderr[-1500:])
    line = first_line(r.stderr)
    assert line.startswith("react3d convert: error: ") and str(path) in line and words in line, r.stderr[-2000:]
    assert "Traceback" not in r.stderr


def test_half_size_depth_pngs_are_refused(scan: Path, tmp_path: Path) -> None:
    """Depth at 128x96 where 256x192 is declared used to give wrong cavity depths with rc 0."""
    s = _copy(scan, tmp_path)
    loaded = load_scene(s)
    (s / "iphone" / "depth").mkdir()
    for i, f in enumerate(loaded.frames):
        d = np.round(read_depth(f.depth, f.depth_scale) * 1000).astype(np.uint16)
        if i == 3:  # one frame re-exported at half size
            d = cv2.resize(d, (d.shape[1] // 2, d.shape[0] // 2), interpolation=cv2.INTER_NEAREST)
        assert cv2.imwrite(str(s / "iphone" / "depth" / f"{f.frame_id}.png"), d)
    (s / "iphone" / "depth.bin").unlink()
    bad = s / "iphone" / "depth" / f"{loaded.frames[3].frame_id}.png"
    r = run_cli_here(["convert", str(s), "--out", str(tmp_path / "out"), *FAST])
    _bad_input(r, bad, "depth image is 128x96 but the scan declares 256x192")
    assert not (tmp_path / "out").exists()


def test_millimetre_mesh_is_refused_with_the_unit(scan: Path, tmp_path: Path) -> None:
    """A millimetre mesh used to give 0 parts, rc 0, 'problems: none'."""
    s = _copy(scan, tmp_path)
    mesh_path = s / "scans" / "mesh_aligned_0.05.ply"
    m = load_mesh(mesh_path)
    save_mesh(mesh_path, TriMesh(m.vertices * 1000.0, m.faces, m.colors))
    r = run_cli_here(["convert", str(s), "--out", str(tmp_path / "out"), *FAST])
    _bad_input(r, mesh_path, "millimetres")
    assert not (tmp_path / "out").exists()


def test_depth_in_another_unit_than_the_mesh_is_refused(scan: Path, tmp_path: Path) -> None:
    """A mesh 20x too large (a room of ~90 units passes the extent check): the depth/mesh ratio catches it."""
    from react3d_core.errors import InputError
    from react3d_core.scene_io.scale import check_scale

    loaded = load_scene(scan)
    m = load_mesh(loaded.mesh_path)
    check_scale(loaded, m)  # the real scan passes
    big = TriMesh(m.vertices * 20.0, m.faces, m.colors)
    try:
        check_scale(loaded, big)
    except InputError as exc:
        assert "the depth frames measure" in str(exc) and str(loaded.mesh_path) in str(exc)
    else:
        raise AssertionError("a mesh 20x off the depth passed the scale check")


def test_truncated_jpeg_is_an_error_not_a_warning(scan: Path, tmp_path: Path) -> None:
    s = _copy(scan, tmp_path)
    jpg = sorted((s / "iphone" / "rgb").glob("*.jpg"))[4]
    data = jpg.read_bytes()
    jpg.write_bytes(data[: len(data) // 2])
    assert cv2.imread(str(jpg)) is not None  # what made this silent: libjpeg decodes it with a warning
    r = run_cli_here(["convert", str(s), "--out", str(tmp_path / "out"), *FAST])
    _bad_input(r, jpg, "truncated JPEG")
