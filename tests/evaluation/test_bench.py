"""Bench plumbing: set files parse, failures are reported per scene, the table prints; densify keeps ids."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from flows.bench.runner import SETS_DIR, load_spec, print_table, run_bench, run_isolated
from react3d_core.data.mesh import TriMesh, load_mesh, save_mesh
from react3d_core.errors import InputError

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


def test_set_files_are_valid(tmp_path):
    heldout = load_spec("heldout", tmp_path)
    assert 9 <= len(heldout) <= 12 and all(e["seed"] >= 100 for e in heldout)
    assert {e["source"] for e in heldout} == {"procedural", "scene-synthesizer"}
    assert len({e["name"] for e in heldout}) == len(heldout)
    smoke = load_spec(str(SETS_DIR / "smoke.json"), tmp_path, frames=12)
    assert len(smoke) == 2 and all(e["n_frames"] == 12 for e in smoke)


def test_set_files_ship_as_package_data():
    """A non-editable install finds the sets: they sit in the flows.bench package and pyproject ships them."""
    import tomllib

    import flows.bench

    assert SETS_DIR == Path(flows.bench.__file__).parent / "sets"
    assert {"heldout.json", "smoke.json"} <= {p.name for p in SETS_DIR.glob("*.json")}
    pyproject = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    assert "sets/*.json" in pyproject["tool"]["setuptools"]["package-data"]["flows.bench"]


def test_bad_spec_is_input_error(tmp_path):
    with pytest.raises(InputError):
        load_spec(str(tmp_path / "nothing_*"), tmp_path)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"scenes": [{"source": "procedural"}]}))  # no seed
    with pytest.raises(InputError):
        load_spec(str(bad), tmp_path)


def test_failed_scene_is_reported_not_raised(tmp_path, capsys):
    entries = [{"name": "empty_scene", "scene_dir": str(tmp_path / "gone")}]  # checked before spawning
    res = run_bench(entries, tmp_path / "out", {"perception": {"backend": "oracle"}})
    assert res["scenes"] == [] and res["failed"][0]["scene"] == "empty_scene"
    print_table(res)
    assert "failed" in capsys.readouterr().out


def _scaling():
    spec = importlib.util.spec_from_file_location("scaling", Path(__file__).parents[2] / "benchmarks" / "scaling.py")
    scaling = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(scaling)
    return scaling


def test_scaling_plot_writes_png(tmp_path):
    runs = [{"frames": n, "faces": None, "wall_s": n / 10, "peak_rss_mb": 100 + n, "stages": {"fusion": n / 20}} for n in (75, 150)]
    _scaling().plot({"vs_frames": runs + [{"frames": 300, "error": "x"}], "vs_faces": []}, tmp_path / "s.png")
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_densify_keeps_original_vertices(tmp_path):
    scaling = _scaling()
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    f = np.array([[0, 1, 2], [1, 3, 2]])
    (tmp_path / "s" / "scans").mkdir(parents=True)
    save_mesh(tmp_path / "s" / "scans" / "mesh_aligned_0.05.ply", TriMesh(v, f))
    assert scaling.densify(tmp_path / "s", 30) == 32  # 2 -> 8 -> 32 faces
    m = load_mesh(tmp_path / "s" / "scans" / "mesh_aligned_0.05.ply")
    np.testing.assert_allclose(m.vertices[:4], v)


@pytest.mark.slow
def test_smoke_set_end_to_end(tmp_path):
    pytest.importorskip("react3d_core.synthetic")
    pytest.importorskip("flows.convert_scene")
    res = run_bench(load_spec("smoke", tmp_path, frames=20), tmp_path, {"perception": {"backend": "oracle"}})
    assert not res["failed"], res["failed"]
    assert res["aggregate"]["0.25"]["f1"] is not None


def _start_prefect_server() -> int:
    """What a converted scene does in a benchmark child: start Prefect's temporary server, whose stop is an
    atexit hook; Prefect's services register later hooks that run first and take a while (simulated)."""
    import atexit
    import time

    from prefect.server.api.server import SubprocessASGIServer

    s = SubprocessASGIServer()
    s.start()
    atexit.register(time.sleep, 3)
    return s.server_process.pid


def test_isolated_run_leaves_no_prefect_server_behind(prefect_home_copy, tmp_path, monkeypatch):
    import psutil

    monkeypatch.setenv("PREFECT_HOME", str(prefect_home_copy(tmp_path / "home")))  # migrated: starts in seconds
    pid = run_isolated(_start_prefect_server)
    alive = psutil.pid_exists(pid) and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    if alive:
        psutil.Process(pid).kill()
    assert not alive, "the benchmark child left its Prefect server running"
