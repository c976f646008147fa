"""The shared store on a real S3-compatible server (s3rver keeps objects on disk): two workers with their
own mirrors share objects and sealed folders, outputs publish to s3:// under a fresh prefix with their
pointer last, and a prefix holding someone else's files is refused. Fast (~5 s); skipped where s3rver is not installed."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from deployments.local_cluster import S3Server, s3rver_command

pytestmark = pytest.mark.skipif(s3rver_command() is None, reason="s3rver not installed (bash scripts/setup.sh test)")


@pytest.fixture()
def remote(s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    for k, v in s3.env.items():
        monkeypatch.setenv(k, v)
    url = s3.url(tmp_path.name)
    monkeypatch.setenv("REACT3D_STORE", url)
    return url


def _as_worker(monkeypatch: pytest.MonkeyPatch, mirror: Path) -> None:
    monkeypatch.setenv("REACT3D_CACHE", str(mirror))
    from tasks import store

    store.clear_decoded()
    store._verified.clear()


def test_objects_and_sealed_folders_reach_a_second_worker(remote: str, tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    from tasks import storage, store

    _as_worker(monkeypatch, tmp_path / "a")
    h = store.put({"v": np.arange(7)}, "perception")
    assert not Path(h["path"]).is_absolute()  # records name no worker's folders
    folder = tmp_path / "a" / "scenes" / "ab" / "export-x"
    folder.mkdir(parents=True)
    (folder / "scene.json").write_text("{}")
    (folder / "m").mkdir()
    (folder / "m" / "part.ply").write_bytes(b"ply")
    store.seal_dir(folder)

    _as_worker(monkeypatch, tmp_path / "b")  # another machine: empty mirror, same REACT3D_STORE
    assert (store.get(h)["v"] == np.arange(7)).all()
    store.verify_handles({"sha256": "x", "path": "scenes/ab/export-x/scene.json", "kind": "exported-scene"})
    assert (tmp_path / "b" / "scenes" / "ab" / "export-x" / "m" / "part.ply").read_bytes() == b"ply"

    # a corrupt copy on the remote is caught on the next worker and quarantined there
    fs, path = storage.filesystem(f"{remote}/{h['path']}")
    fs.pipe_file(path, fs.cat_file(path)[:-3] + b"xyz")
    _as_worker(monkeypatch, tmp_path / "c")
    with pytest.raises(store.CorruptObjectError):
        store.get(h)


def test_publish_tree_writes_a_fresh_prefix_and_its_pointer_and_refuses_foreign_prefixes(remote: str, tmp_path: Path) -> None:
    from react3d_core.atomic import OUTPUT_MARKER
    from react3d_core.errors import InputError
    from tasks import storage

    local = tmp_path / "scene"
    (local / "meshes").mkdir(parents=True)
    (local / OUTPUT_MARKER).write_text("{}")
    (local / "meshes" / "a.ply").write_bytes(b"a")
    (local / "scene.json").write_text(json.dumps({"objects": [1, 2], "input_mesh": "../scan.ply"}))
    url = f"{remote}/out/s0"
    manifest = storage.publish_tree(local, url)
    assert manifest == storage.output_manifest(url)
    assert json.loads(storage.read_text(manifest))["input_mesh"] == str((tmp_path / "scan.ply").resolve())
    first = storage.read_pointer(url)["prefix"]
    (local / "meshes" / "a.ply").unlink()
    (local / "meshes" / "b.ply").write_bytes(b"b")
    storage.publish_tree(local, url)  # a rerun goes to a fresh prefix; the previous one stays for its readers
    second = storage.read_pointer(url)["prefix"]
    storage.publish_tree(local, url)  # the one before the previous is removed
    third = storage.read_pointer(url)["prefix"]
    fs, path = storage.filesystem(url)
    assert len({first, second, third}) == 3
    files = [OUTPUT_MARKER, "meshes/b.ply", "scene.json"]
    assert sorted(p[len(path) + 1:] for p in fs.find(path)) == sorted(
        [OUTPUT_MARKER, storage.OUTPUT_POINTER] + [f"{v}/{f}" for v in (second, third) for f in files])
    assert sorted(storage.read_pointer(url)["files"]) == files

    fs.pipe_file(f"{storage.filesystem(remote)[1]}/theirs/data.csv", b"1,2")
    with pytest.raises(InputError, match="did not write"):
        storage.publish_tree(local, f"{remote}/theirs")


def test_result_storage_follows_the_store(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from tasks import storage

    assert storage.result_storage_env("s3://b/p") == {"PREFECT_RESULTS_DEFAULT_STORAGE_BLOCK": "remote-file-system/react3d-results"}
    assert storage.result_storage_env(str(tmp_path)) == {"PREFECT_LOCAL_STORAGE_PATH": str(tmp_path / "prefect-results")}
    monkeypatch.setenv("REACT3D_STORE", f"file://{tmp_path}")
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "ignored"))
    assert storage.cache_root() == tmp_path  # a shared folder is the store itself on every worker


def test_listing_past_one_page(remote: str) -> None:
    """A scene output holds > 1000 files (collision pieces): listings page with continuation tokens."""
    from tasks import storage

    fs, path = storage.filesystem(f"{remote}/many")
    fs.pipe({f"{path}/k{i:04d}": b"" for i in range(1001)})
    assert len(fs.find(path)) == 1001
