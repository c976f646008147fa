"""Remote outputs readers can trust, on the S3 server: a publication goes under a fresh prefix with its pointer
written last; readers (``view``, ``export``, ``evaluate``) follow the pointer, check every object against it
and refuse an output whose pointer is missing or whose objects do not match it; a reader polling during a
republication only ever sees a whole output. Fast; skipped where s3rver is not installed."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import numpy as np
import pytest

from deployments.local_cluster import s3rver_command

pytestmark = pytest.mark.skipif(s3rver_command() is None, reason="s3rver not installed (bash scripts/setup.sh test)")


@pytest.fixture()
def remote(s3_prefix: str) -> str:
    return s3_prefix


def _output(folder: Path, tag: str, n_extra: int = 0) -> Path:
    """A small conversion output: a scan mesh, a background, a manifest, the marker; ``tag`` in every file."""
    import trimesh

    from react3d_core.atomic import OUTPUT_MARKER
    from react3d_core.data import InteractiveScene, TriMesh, save_mesh

    (folder / "meshes").mkdir(parents=True)
    box = trimesh.creation.box(extents=[1, 1, 1])
    mesh = TriMesh(np.asarray(box.vertices), np.asarray(box.faces), np.full((len(box.vertices), 3), 200, np.uint8))
    save_mesh(folder / "scan.ply", mesh)
    save_mesh(folder / "meshes" / "background.ply", mesh)
    for i in range(n_extra):
        (folder / "meshes" / f"piece_{i:03d}.txt").write_text(f"{tag}-{i}")
    (folder / "version.txt").write_text(tag)
    (folder / OUTPUT_MARKER).write_text("{}")
    InteractiveScene(scene_id=tag, input_mesh="scan.ply", background_mesh="meshes/background.ply",
                     objects=[]).save(folder / "scene.json")
    return folder


def test_view_reads_a_published_output_through_its_pointer(remote: str, tmp_path: Path) -> None:
    from flows.viewer_server import make_viewer_server
    from tasks import storage

    storage.publish_tree(_output(tmp_path / "a", "one"), f"{remote}/out/s0")
    copy = storage.fetch_output(f"{remote}/out/s0")
    assert (copy / "version.txt").read_text() == "one" and (copy / "meshes" / "background.ply").is_file()
    server, url = make_viewer_server(copy, port=0)
    server.server_close()
    assert url.startswith("http://127.0.0.1:")
    # a dataset's --out: one local folder with a sub-folder per scene, for `evaluate`
    storage.publish_tree(_output(tmp_path / "b", "two"), f"{remote}/out/s1")
    root = storage.fetch_outputs(f"{remote}/out")
    assert sorted(p.name for p in root.iterdir()) == ["s0", "s1"]
    assert (root / "s1" / "version.txt").read_text() == "two"


def _damage(remote: str, rel: str, data: bytes | None) -> str:
    """Replace (or, with None, remove) one object of ``out/s0``'s current publication; its URL."""
    from tasks import storage

    url = f"{remote}/out/s0"
    prefix = storage.read_pointer(url)["prefix"]
    fs, path = storage.filesystem(f"{url}/{prefix}/{rel}")
    if data is None:
        fs.rm_file(path)
    else:
        fs.pipe_file(path, data)
    return url


@pytest.mark.parametrize(("rel", "data", "why"), [
    ("version.txt", b"on", "has 2 bytes, its react3d-output.json says 3"),  # truncated
    ("version.txt", b"two", "does not match the sha256 in its react3d-output.json"),  # same size, other bytes
    ("meshes/background.ply", None, "is missing"),
    ("meshes/extra.ply", b"x", "is not listed in its react3d-output.json"),
])
def test_readers_refuse_an_output_that_does_not_match_its_pointer(remote: str, tmp_path: Path, rel: str,
                                                                  data: bytes | None, why: str,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main
    from tasks import storage

    storage.publish_tree(_output(tmp_path / "a", "one"), f"{remote}/out/s0")
    url = _damage(remote, rel, data)
    (tmp_path / "gt").mkdir()
    for cmd in (["view", url], ["export", url, "--to", str(tmp_path / "x")], ["evaluate", url, str(tmp_path / "gt")]):
        assert main(cmd) == 2, cmd
        err = capsys.readouterr().err
        assert why in err and len(err.strip().splitlines()) == 1, (cmd, err)
    assert not (tmp_path / "x").exists() and not list((tmp_path / "cache").glob("outputs/*/s0"))


def test_readers_refuse_an_output_without_its_pointer(remote: str, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main
    from tasks import storage

    url = f"{remote}/out/s0"
    storage.publish_tree(_output(tmp_path / "a", "one"), url)
    fs, path = storage.filesystem(url)
    fs.rm_file(f"{path}/{storage.OUTPUT_POINTER}")  # e.g. a publication killed before its pointer
    assert main(["view", url]) == 2
    assert "has no react3d-output.json: not a published react3d output" in capsys.readouterr().err
    fs.pipe_file(f"{path}/{storage.OUTPUT_POINTER}", json.dumps({"prefix": "v/../../other", "files": {}}).encode())
    assert main(["export", url, "--to", str(tmp_path / "x")]) == 2
    assert "names files outside its output; refusing it" in capsys.readouterr().err


def test_a_reader_polling_during_a_republication_sees_only_whole_outputs(remote: str, tmp_path: Path) -> None:
    from tasks import storage

    url = f"{remote}/out/s0"
    storage.publish_tree(_output(tmp_path / "a", "one", n_extra=40), url)
    new = _output(tmp_path / "b", "two", n_extra=40)
    seen: list[str] = []
    done = threading.Event()

    errors: list[BaseException] = []

    def republish() -> None:
        try:
            for _ in range(3):
                storage.publish_tree(new, url)
        except BaseException as exc:  # noqa: BLE001 - reported by the test below
            errors.append(exc)
        finally:
            done.set()

    th = threading.Thread(target=republish)
    th.start()
    reads = 0
    while not done.is_set() or reads == 0:
        try:
            copy = storage.fetch_output(url)
        except Exception as exc:  # noqa: BLE001 - only "replaced meanwhile" may interrupt a read
            assert "replaced or removed meanwhile" in str(exc) or "is missing" in str(exc), exc
            continue
        reads += 1
        tags = {(copy / "version.txt").read_text()} | {p.read_text().split("-")[0] for p in (copy / "meshes").glob("piece_*.txt")}
        assert len(tags) == 1 and len(list((copy / "meshes").glob("piece_*.txt"))) == 40, tags
        seen.append(tags.pop())
    th.join()
    assert not errors, errors
    assert storage.fetch_output(url).joinpath("version.txt").read_text() == "two"
    assert seen and set(seen) <= {"one", "two"}
    print(f"{reads} whole reads during 3 republications: {seen.count('one')} old, {seen.count('two')} new")
