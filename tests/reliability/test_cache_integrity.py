"""The content store is verified, not trusted. A flipped byte in a stored object or a
stored export folder is caught (one warning line), quarantined and recomputed; the corrupt copy never
reaches a user's output; temporaries of killed runs are swept."""

from __future__ import annotations

import logging
import os
import socket
import hashlib
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from .conftest import convert_oracle_urdf as convert, copy_first_run

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


def _flip(path: Path, at: float = 0.5) -> None:
    data = bytearray(path.read_bytes())
    i = int(len(data) * at)
    data[i] ^= 0x20
    path.write_bytes(bytes(data))


@pytest.fixture()
def store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_flipped_object_is_quarantined_then_healed_by_put(store: Path, caplog: pytest.LogCaptureFixture) -> None:
    from react3d_core.errors import InputError
    from tasks.store import CorruptObjectError, get, put

    obj = {"masks": np.arange(5000, dtype=np.int32).reshape(50, 100), "name": "x"}
    h = put(obj, "perception")
    _flip(store / h["path"])
    with caplog.at_level(logging.WARNING, logger="react3d.cache"), pytest.raises(CorruptObjectError) as e:
        get(h, cache=False)
    assert isinstance(e.value, InputError) and "quarantined" in str(e.value)  # one clear line, not BadZipFile
    assert len([r for r in caplog.records if r.name == "react3d.cache"]) == 1
    assert not (store / h["path"]).exists() and len(list((store / "quarantine").iterdir())) == 1
    # the next run recomputes the same content: put() writes it again and it reads back intact
    assert put(obj, "perception") == h
    assert np.array_equal(get(h, cache=False)["masks"], obj["masks"])


def test_put_rewrites_a_corrupt_existing_object(store: Path) -> None:
    from tasks.store import get, put

    h = put([1, 2, 3], "candidates")
    _flip(store / h["path"], 0.9)
    put([1, 2, 3], "candidates")  # before: skipped because the file existed, so it never healed
    assert get(h, cache=False) == [1, 2, 3]


def test_sealed_folder_verification(store: Path) -> None:
    from tasks.store import CorruptObjectError, seal_dir, verify_dir

    def make(name: str) -> Path:
        d = store / "scenes" / "ab" / name
        (d / "export" / "urdf").mkdir(parents=True)
        (d / "scene.json").write_text('{"objects": []}')
        (d / "export" / "urdf" / "scene.urdf").write_text("<robot name='s'><link name='base'/></robot>")
        return d

    ok = make("export-ok")
    seal_dir(ok)
    verify_dir(ok)
    flipped = make("export-flipped")
    seal_dir(flipped)
    _flip(flipped / "export" / "urdf" / "scene.urdf")
    with pytest.raises(CorruptObjectError, match="scene.urdf"):
        verify_dir(flipped)
    assert not flipped.exists()
    extra = make("export-extra")
    seal_dir(extra)
    (extra / "stray.txt").write_text("x")
    with pytest.raises(CorruptObjectError):
        verify_dir(extra)
    unsealed = make("export-unsealed")
    with pytest.raises(CorruptObjectError, match="no seal"):
        verify_dir(unsealed)
    assert ok.exists() and sorted(p.name.split(".")[0] for p in (store / "quarantine").iterdir()
                                  if not p.name.endswith(".seal.json")) == ["export-extra", "export-flipped", "export-unsealed"]


def test_record_pointing_at_a_corrupt_object_is_a_cache_miss(store: Path) -> None:
    """What the Prefect guard does with a valid JSON record whose object no longer verifies."""
    from tasks.store import CorruptObjectError, put, verify_handles

    h = put({"a": np.ones(100)}, "perception")
    verify_handles({**h, "seconds": 1.0})
    _flip(store / h["path"])
    with pytest.raises(CorruptObjectError):
        verify_handles([{**h, "seconds": 1.0}])
    with pytest.raises(CorruptObjectError, match="outside the store"):
        verify_handles({"sha256": "0" * 64, "path": "/etc/passwd", "kind": "perception"})


def test_stale_temporaries_of_killed_runs_are_swept(store: Path) -> None:
    from tasks.store import STALE_TMP_SECONDS, sweep_stale

    host = hashlib.sha1(socket.gethostname().encode()).hexdigest()[:8]
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    scenes, objects = store / "scenes" / "cd", store / "objects" / "ab"
    old_style = scenes / ".export-cd34.k2j3h4.tmp"            # atomic_dir of earlier releases: no pid
    fresh_old_style = scenes / ".export-ef56.a1b2c3.tmp"       # could still be written: kept
    dead_pid = scenes / f".export-cd78.tmp-{dead.pid}@{host}-ab12"
    live_pid = scenes / f".export-cd90.tmp-{os.getpid()}@{host}-cd34"
    for d in (old_style, fresh_old_style, dead_pid, live_pid):
        (d / "export").mkdir(parents=True)
        (d / "export" / "scene.urdf").write_text("partial")
    objects.mkdir(parents=True)
    npz_tmp = objects / ".ab12.x8y9.tmp.npz"
    npz_tmp.write_bytes(b"partial")
    real = scenes / "export-cd34"
    real.mkdir()
    past = time.time() - STALE_TMP_SECONDS - 60
    for p in (old_style, npz_tmp, real):
        os.utime(p, (past, past))
    removed = sweep_stale(force=True)
    assert sorted(p.name for p in removed) == sorted([old_style.name, dead_pid.name, npz_tmp.name])
    assert fresh_old_style.exists() and live_pid.exists() and real.exists()


# --- a real convert over a corrupted store ----------------------------------------------------------------

def test_convert_recomputes_flipped_export_and_objects(synthetic_scene, dresser_first_run: Path, prefect_server,  # noqa: ANN001
                                                       tmp_path: Path) -> None:
    scene = synthetic_scene(seed=5, n_frames=12, kind="dresser")
    env = copy_first_run(dresser_first_run, tmp_path / "home", tmp_path / "a", prefect_server.home)  # first run: done
    cache = Path(env["REACT3D_CACHE"])
    urdfs = sorted(cache.glob("scenes/*/export-*/export/urdf/scene.urdf"))
    objects = sorted(cache.glob("objects/*/*.npz"))
    assert len(urdfs) == 1 and objects
    _flip(urdfs[0])                   # the cached export the next run would publish
    for p in objects:                 # every perception / candidate / part object
        _flip(p, 0.6)

    second = convert(scene, tmp_path / "b", env)

    assert second.returncode == 0, second.stderr[-3000:]
    published = tmp_path / "b" / "export" / "urdf" / "scene.urdf"
    ET.parse(published)  # well-formed
    assert published.read_bytes() == (tmp_path / "a" / "export" / "urdf" / "scene.urdf").read_bytes()
    warnings = [ln for ln in second.stderr.splitlines() if "moved to" in ln and "recomputing" in ln]
    assert 1 + len(objects) >= len(warnings) >= 2  # one line per corrupt thing found (export + objects read)
    assert "BadZipFile" not in second.stderr and "Traceback" not in second.stderr
    quarantined = [p for p in (cache / "quarantine").iterdir() if not p.name.endswith(".seal.json")]
    assert any(p.name.startswith("export-") for p in quarantined) and any(".npz." in p.name for p in quarantined)
    assert ET.parse(urdfs[0]) and urdfs[0].read_bytes() == published.read_bytes()  # the store healed
