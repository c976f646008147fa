"""Input scans read from the S3 server through the bounded scan cache: the same content keys as the local
folder, reuse while unchanged, a fresh download when the remote or the local copy changed, least recently
used eviction that spares scans in use, one line for a scan that cannot fit or a download that does not
match the store. Fast; skipped where s3rver is not installed."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from deployments.local_cluster import s3rver_command

pytestmark = pytest.mark.skipif(s3rver_command() is None, reason="s3rver not installed (bash scripts/setup.sh test)")


@pytest.fixture()
def bucket(s3_prefix: str) -> str:
    return s3_prefix


def _upload(url: str, files: dict[str, bytes]) -> None:
    from tasks import storage

    fs, path = storage.filesystem(url)
    fs.pipe({f"{path}/{rel}": data for rel, data in files.items()})


def _scan(tag: str, size: int = 1000) -> dict[str, bytes]:
    return {"scans/mesh.ply": tag.encode() * (size // len(tag)), "iphone/pose.json": b"{}", ".hidden": b"x"}


def test_a_scan_in_the_bucket_keeps_its_content_keys(bucket: str, synthetic_scene) -> None:  # noqa: ANN001
    from flows.convert_dataset import find_scenes
    from tasks import scan_cache
    from tasks.store import tree_fingerprint

    scene = synthetic_scene(seed=3, n_frames=16, kind="dresser")
    files = {p.relative_to(scene).as_posix(): p.read_bytes() for p in scene.rglob("*") if p.is_file()}
    _upload(f"{bucket}/scans/dresser", files)
    _upload(f"{bucket}/scans/notes", {"readme.txt": b"not a scan"})
    assert [s.url for s in find_scenes(f"{bucket}/scans")] == [f"{bucket}/scans/dresser"]
    with scan_cache.local_scene(f"{bucket}/scans/dresser") as local:
        copy = tree_fingerprint(local, exclude=("report", "export"))  # the scene hash every key builds on
    assert copy == tree_fingerprint(scene, exclude=("report", "export"))


def test_reused_while_unchanged_downloaded_again_when_changed(bucket: str) -> None:
    from tasks import scan_cache

    url = f"{bucket}/s0"
    _upload(url, _scan("a"))
    with scan_cache.local_scene(url) as local:
        mesh = local / "scans" / "mesh.ply"
        assert mesh.read_bytes() == b"a" * 1000 and not (local / ".hidden").exists()
        first = mesh.stat().st_ino
    with scan_cache.local_scene(url) as local:
        assert mesh.stat().st_ino == first  # no download
    _upload(url, {"scans/mesh.ply": b"b" * 999})  # changed on the remote
    with scan_cache.local_scene(url) as local:
        assert (local / "scans" / "mesh.ply").read_bytes() == b"b" * 999
    (local / "scans" / "mesh.ply").write_bytes(b"b" * 10)  # the local copy damaged
    with scan_cache.local_scene(url) as local:
        assert (local / "scans" / "mesh.ply").read_bytes() == b"b" * 999


def test_least_recently_used_scans_are_evicted_but_not_those_in_use(bucket: str,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    from react3d_core.errors import InputError
    from tasks import scan_cache

    for name in ("a", "b", "c", "d"):
        _upload(f"{bucket}/{name}", _scan(name))  # 1002 bytes each without the hidden file
    monkeypatch.setenv("REACT3D_SCAN_CACHE_GB", str(2500 / 1e9))  # two scans fit

    def cached() -> set[str]:
        return {p.name for p in scan_cache.cache_dir().glob("*/*") if p.is_dir()}

    for name in ("a", "b", "a"):  # a used last
        with scan_cache.local_scene(f"{bucket}/{name}"):
            pass
        time.sleep(0.02)
    with scan_cache.local_scene(f"{bucket}/c"):
        pass
    assert cached() == {"a", "c"}  # b was the least recently used
    with scan_cache.local_scene(f"{bucket}/a"):  # in use by a conversion: c goes instead, although newer
        with scan_cache.local_scene(f"{bucket}/d"):
            assert cached() == {"a", "d"}
            with pytest.raises(InputError, match="scans being converted"):  # both in use: no room for a third
                with scan_cache.local_scene(f"{bucket}/b"):
                    pass
    monkeypatch.setenv("REACT3D_SCAN_CACHE_GB", str(500 / 1e9))
    with pytest.raises(InputError, match="more than the scan cache holds"):
        with scan_cache.local_scene(f"{bucket}/b"):
            pass


def test_a_download_that_does_not_match_the_listing_is_refused(bucket: str) -> None:
    """The object changes between the listing and the download (same size, other bytes): its MD5 ETag
    no longer matches, and nothing is cached."""
    from react3d_core.errors import InputError
    from tasks import scan_cache

    url = f"{bucket}/s0"
    _upload(url, _scan("a"))
    listing = scan_cache._listing(url)
    _upload(url, {"scans/mesh.ply": b"z" * 1000})
    root = scan_cache.cache_dir()
    root.mkdir(parents=True, exist_ok=True)
    with pytest.raises(InputError, match="do not match the store"):
        scan_cache._download(url, listing, "k", root / "k.json", root / "k" / "s0")
    assert not (root / "k.json").exists() and not (root / "k" / "s0").exists()
    assert os.listdir(root / "k") == []  # no temporary left


def test_a_dataset_in_the_bucket_is_listed_like_a_folder(bucket: str, tmp_path: Path) -> None:
    from flows.convert_dataset import check_dataset_outputs
    from react3d_core.errors import InputError

    for name in ("a1", "a2", "b1"):
        _upload(f"{bucket}/scans/{name}", _scan(name))
    _upload(f"{bucket}/scans/zz", {"readme.txt": b"not a scan"})
    _upload(f"{bucket}/scans/deep", {"scans/mesh_aligned_0.05.ply": b"ply"})  # nothing at its own level
    names = lambda scenes: [s.name for s in scenes]  # noqa: E731
    assert names(check_dataset_outputs(f"{bucket}/scans", None, None, tmp_path / "out")) == ["a1", "a2", "b1", "deep"]
    assert names(check_dataset_outputs(f"{bucket}/scans", None, "a*", tmp_path / "out")) == ["a1", "a2"]
    assert [str(s) for s in check_dataset_outputs(f"{bucket}/scans", ["b1"], None, tmp_path / "out")] == [f"{bucket}/scans/b1"]
    with pytest.raises(InputError, match="dataset prefix not found"):
        check_dataset_outputs(f"{bucket}/nothing", None, None, tmp_path / "out")
