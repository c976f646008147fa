"""Faults of an object store, on the real S3 server (s3rver keeps objects as files on disk): the server
killed mid-upload and restarted, killed for longer than the retry budget, objects truncated or damaged
behind its back (a scan file, a cache object, a published output, its pointer), wrong credentials, and a
local disk that cannot hold a download. Each gives one line naming what and where, a retry where that
helps, nothing half published and no silent wrong result. Fast (~1 min); skipped without s3rver."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from deployments.local_cluster import ROOT, S3Server, s3rver_command

pytestmark = [pytest.mark.integration, pytest.mark.skipif(s3rver_command() is None, reason="s3rver not installed (bash scripts/setup.sh test)")]


@pytest.fixture()
def own_s3(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[S3Server]:
    """A server of this test's own (tests here kill it), clients pointed at it, a local cache under tmp_path."""
    srv = S3Server(tmp_path / "s3" / "data")
    for k, v in srv.env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    for k in ("REACT3D_STORE", "REACT3D_SCAN_CACHE_GB", "REACT3D_STORE_RETRY_SECONDS"):
        monkeypatch.delenv(k, raising=False)
    yield srv
    srv.close()


def _output(folder: Path, tag: str, big: int = 0) -> Path:
    """A conversion output as publish_tree sees it: marker, manifest, a mesh, ``big`` random bytes."""
    from react3d_core.atomic import OUTPUT_MARKER

    (folder / "meshes").mkdir(parents=True)
    (folder / OUTPUT_MARKER).write_text("{}")
    (folder / "meshes" / "background.ply").write_bytes(tag.encode() * 5000)
    (folder / "version.txt").write_text(tag)
    if big:
        (folder / "meshes" / "big.bin").write_bytes(np.random.default_rng(0).bytes(big))
    (folder / "scene.json").write_text(json.dumps({"scene_id": tag, "objects": []}))
    return folder


def _truncate(path: Path, keep: int) -> None:
    with open(path, "r+b") as fh:
        fh.truncate(keep)


def _one_line(exc: BaseException) -> str:
    text = str(exc)
    assert "\n" not in text.strip(), text
    return text


# --- the store killed and restarted ---------------------------------------------------------------------

def test_store_killed_mid_upload_and_restarted_the_publication_finishes_whole(
        own_s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    from tasks import storage

    monkeypatch.setenv("REACT3D_STORE_RETRY_SECONDS", "90")
    local = _output(tmp_path / "scene", "one", big=120_000_000)  # above twice s3fs's 50 MB part size: a multipart upload
    url = own_s3.url("out/s0")
    done: dict[str, object] = {}

    def publish() -> None:
        try:
            done["manifest"] = storage.publish_tree(local, url)
        except BaseException as exc:  # noqa: BLE001 - asserted below
            done["error"] = exc

    caplog.set_level(logging.WARNING, logger="react3d.store")
    th = threading.Thread(target=publish)
    th.start()
    uploads = own_s3.data / own_s3.bucket / "._S3rver_uploads"
    deadline = time.time() + 60
    while not any(p.is_file() and p.stat().st_size > 0 and not p.name.endswith(".md5")
                  for p in (uploads.rglob("*") if uploads.is_dir() else [])):  # a part is being written
        assert time.time() < deadline and th.is_alive(), f"no multipart upload seen: {done}"
        time.sleep(0.02)
    pointer_file = own_s3.object_file(f"out/s0/{storage.OUTPUT_POINTER}")
    assert not pointer_file.exists()  # the pointer is written last
    own_s3.kill()
    time.sleep(10)  # connections refused meanwhile, longer than botocore's own retries
    assert th.is_alive() and not pointer_file.exists()
    own_s3.start()
    th.join(timeout=240)
    assert "error" not in done, done.get("error")
    retries = [r.getMessage() for r in caplog.records if "did not answer" in r.getMessage()]
    assert retries and own_s3.env["AWS_ENDPOINT_URL"] in retries[0], retries
    copy = storage.fetch_output(url)  # every object checked against the pointer's sha256
    assert (copy / "meshes" / "big.bin").read_bytes() == (local / "meshes" / "big.bin").read_bytes()
    fs, path = storage.filesystem(url)
    versions = {p[len(path) + 1:].split("/")[1] for p in fs.find(f"{path}/{storage.VERSIONS_DIR}")}
    assert len(versions) == 1, versions  # the retried upload went to the same fresh prefix


def test_store_down_past_the_retry_budget_one_line_and_the_old_output_stays(
        own_s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from tasks import storage
    from tasks.remote_fs import StoreUnavailableError
    from tasks.retry import is_transient

    url = own_s3.url("out/s0")
    storage.publish_tree(_output(tmp_path / "a", "one"), url)
    first = storage.read_pointer(url)
    monkeypatch.setenv("REACT3D_STORE_RETRY_SECONDS", "3")
    own_s3.kill()
    t0 = time.time()
    with pytest.raises(StoreUnavailableError) as err:
        storage.publish_tree(_output(tmp_path / "b", "two"), url)
    line = _one_line(err.value)
    assert line.startswith(url) and f"the store at {own_s3.env['AWS_ENDPOINT_URL']} did not answer" in line, line
    assert "REACT3D_STORE_RETRY_SECONDS" in line and time.time() - t0 < 60
    assert is_transient(err.value)  # Prefect's retry condition and the dataset table retry it
    own_s3.start()
    assert storage.read_pointer(url)["prefix"] == first["prefix"]  # nothing of "two" is visible
    assert (storage.fetch_output(url) / "version.txt").read_text() == "one"


# --- truncated or damaged objects -------------------------------------------------------------------------

def test_a_scan_object_truncated_in_the_store_is_refused_and_not_cached(own_s3: S3Server) -> None:
    from tasks import scan_cache, storage

    url = own_s3.url("scans/s0")
    mesh = np.random.default_rng(1).bytes(200_000)
    fs, path = storage.filesystem(url)
    fs.pipe({f"{path}/scans/mesh.ply": mesh, f"{path}/iphone/pose.json": b"{}"})
    _truncate(own_s3.object_file("scans/s0/scans/mesh.ply"), 150_000)  # the listing says 150000, the ETag the old MD5
    with pytest.raises(scan_cache.ScanMismatchError) as err:
        with scan_cache.local_scene(url):
            pass
    line = _one_line(err.value)
    assert line.startswith(f"{url}/scans/mesh.ply: ") and "damaged in the store" in line, line
    assert not list(scan_cache.cache_dir().glob("*.json"))  # no record: nothing half cached
    assert not [p for p in scan_cache.cache_dir().rglob("*") if p.is_file() and p.suffix != ".lock"]
    fs.pipe_file(f"{path}/scans/mesh.ply", mesh)  # uploaded again: read whole
    with scan_cache.local_scene(url) as local:
        assert (local / "scans" / "mesh.ply").read_bytes() == mesh


def test_a_cache_object_truncated_in_the_store_is_quarantined_recomputed_and_healed(
        own_s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from tasks import store

    monkeypatch.setenv("REACT3D_STORE", own_s3.url("store"))

    def worker(name: str) -> None:
        monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / name))
        store.clear_decoded()
        store._verified.clear()

    worker("a")
    value = {"v": np.arange(5000)}
    h = store.put(value, "perception")
    _truncate(own_s3.object_file(f"store/{h['path']}"), 100)
    worker("b")
    with pytest.raises(store.CorruptObjectError) as err:
        store.get(h)
    assert str(tmp_path / "b" / h["path"]) in _one_line(err.value) and "quarantined" in str(err.value)
    assert list((tmp_path / "b" / "quarantine").iterdir())
    worker("a")
    assert store.put(value, "perception") == h  # the recomputation uploads it again: the remote size differs
    worker("c")
    assert (store.get(h)["v"] == np.arange(5000)).all()


@pytest.mark.parametrize("damage", ["truncated", "same size, other bytes", "pointer truncated"])
def test_a_published_output_damaged_in_the_store_is_refused_by_readers(
        own_s3: S3Server, tmp_path: Path, damage: str, capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main
    from tasks import storage

    url = own_s3.url("out/s0")
    storage.publish_tree(_output(tmp_path / "a", "one"), url)
    prefix = storage.read_pointer(url)["prefix"]
    obj = own_s3.object_file(f"out/s0/{prefix}/meshes/background.ply")
    if damage == "truncated":
        _truncate(obj, 10)
        expect = f"{url}/{prefix}/meshes/background.ply: has 10 bytes, its react3d-output.json says 15000"
    elif damage == "same size, other bytes":
        obj.write_bytes(b"x" * 15000)
        expect = f"{url}/{prefix}/meshes/background.ply: does not match the sha256 in its react3d-output.json"
    else:
        _truncate(own_s3.object_file(f"out/s0/{storage.OUTPUT_POINTER}"), 40)
        expect = f"{url}/{storage.OUTPUT_POINTER}: is not a readable react3d output pointer"
    with pytest.raises(Exception) as err:
        storage.fetch_output(url)
    assert _one_line(err.value).startswith(expect), err.value
    assert main(["export", url, "--to", str(tmp_path / "x")]) == 2
    assert expect in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


# --- wrong credentials ------------------------------------------------------------------------------------

def test_wrong_credentials_fail_at_once_with_one_line(own_s3: S3Server, tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    from tasks import scan_cache, storage, store
    from tasks.remote_fs import StoreAccessError
    from tasks.retry import is_transient

    scans = own_s3.url("scans")
    fs, path = storage.filesystem(scans)
    fs.pipe({f"{path}/s0/scans/mesh_aligned_0.05.ply": b"ply", f"{path}/s0/iphone/pose.json": b"{}"})
    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "WRONG")
    monkeypatch.setenv("REACT3D_STORE", own_s3.url("store"))
    t0 = time.time()
    with pytest.raises(StoreAccessError) as err:
        store.put({"v": np.arange(3)}, "perception")
    line = _one_line(err.value)
    assert line.startswith(f"{own_s3.url('store')}/objects/") and "refused access" in line and "AWS_ACCESS_KEY_ID" in line
    assert not is_transient(err.value)
    with pytest.raises(StoreAccessError, match=f"^{scans}/s0: the store at .* refused access"):
        with scan_cache.local_scene(f"{scans}/s0"):
            pass
    assert time.time() - t0 < 20  # not retried
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "PREFECT_API"))}
    env["PREFECT_HOME"] = str(tmp_path / "prefect")
    r = subprocess.run([sys.executable, "-m", "flows.cli", "convert-dataset", scans, "--out", own_s3.url("out")],
                       env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    err_lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(err_lines) == 1, r.stderr
    assert "refused access" in err_lines[0] and scans in err_lines[0], err_lines


# --- a local disk that cannot hold the download ------------------------------------------------------------

_UNDER_A_FILE_SIZE_LIMIT = """
import resource, sys
resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))  # no file beyond 100 kB: writes fail with EFBIG
from tasks import scan_cache
try:
    with scan_cache.local_scene(sys.argv[1]):
        print("downloaded")
except Exception as exc:
    print(type(exc).__name__, "|", exc)
"""


def test_a_download_the_local_disk_cannot_hold_is_one_line_and_leaves_nothing(own_s3: S3Server, tmp_path: Path) -> None:
    """A full disk, simulated by a file size limit on the process (RLIMIT_FSIZE: writes past it fail
    with EFBIG, as they fail with ENOSPC on a full disk)."""
    from tasks import scan_cache, storage

    url = own_s3.url("scans/s0")
    fs, path = storage.filesystem(url)
    fs.pipe({f"{path}/scans/mesh.ply": np.random.default_rng(2).bytes(300_000), f"{path}/iphone/pose.json": b"{}"})
    r = subprocess.run([sys.executable, "-c", _UNDER_A_FILE_SIZE_LIMIT, url], env=dict(os.environ), cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    out = r.stdout.strip().splitlines()
    assert len(out) == 1 and out[0].startswith("InputError | "), r.stdout + r.stderr
    assert f"cannot hold the download of {url}/" in out[0] and "(and 1 more) (File too large)" in out[0], out[0]
    assert "REACT3D_CACHE" in out[0] and str(scan_cache.cache_dir()) in out[0]
    assert not list(scan_cache.cache_dir().glob("*.json"))
    assert not [p for p in scan_cache.cache_dir().rglob("*") if p.is_file() and p.suffix != ".lock"]
    with scan_cache.local_scene(url) as local:  # without the limit: downloaded whole
        assert (local / "scans" / "mesh.ply").stat().st_size == 300_000


def test_a_scan_larger_than_the_free_disk_is_refused_before_its_download(tmp_path: Path) -> None:
    import shutil

    from react3d_core.errors import InputError
    from tasks import scan_cache

    free = shutil.disk_usage(tmp_path).free
    scan_cache.check_free_space(tmp_path, free // 2, "s3://b/scans/s0")
    with pytest.raises(InputError, match=rf"^{tmp_path}: the scan s3://b/scans/s0 is .* GB and this disk has .* GB free"):
        scan_cache.check_free_space(tmp_path, free + 10**9, "s3://b/scans/s0")


def test_which_store_errors_are_retried() -> None:
    """Real exception objects as botocore, s3fs and aiohttp raise them: connection and 5xx errors are
    retried, refused credentials and missing objects are not, and a refusal raised while cleaning up
    after a lost connection (s3rver answers 405 to aborting a multipart upload) counts as that lost connection."""
    import errno

    import aiohttp
    from botocore.exceptions import ConnectionClosedError, EndpointConnectionError

    from tasks.remote_fs import StoreUnavailableError, _during_lost_connection, is_store_transient

    lost = EndpointConnectionError(endpoint_url="http://127.0.0.1:1/b/k")
    assert is_store_transient(lost) and is_store_transient(ConnectionClosedError(endpoint_url="http://x"))
    assert is_store_transient(aiohttp.ServerDisconnectedError()) and is_store_transient(ConnectionRefusedError())
    assert is_store_transient(OSError(errno.EBUSY, "SlowDown")) and is_store_transient(OSError(errno.EREMOTEIO, "500"))
    assert not is_store_transient(PermissionError("Forbidden")) and not is_store_transient(FileNotFoundError("k"))
    assert not is_store_transient(OSError(errno.EINVAL, "bad")) and not is_store_transient(ValueError("x"))
    assert not is_store_transient(StoreUnavailableError("already retried for the whole budget"))
    try:
        try:
            raise lost
        except EndpointConnectionError:
            raise PermissionError("The specified method is not allowed against this resource.")  # noqa: B904
    except PermissionError as exc:
        assert _during_lost_connection(exc)
    assert not _during_lost_connection(PermissionError("The AWS Access Key Id you provided does not exist"))
