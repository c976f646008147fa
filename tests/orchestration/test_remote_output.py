"""A conversion of a scan in a bucket, published to the S3 server (the run's Prefect server, a local store),
reads back whole through its pointer: the manifest the flow returns is the one the pointer names, and ``export`` / ``view`` work on
the verified copy. Skipped where s3rver is not installed."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from deployments.local_cluster import S3Server, s3rver_command

pytestmark = [pytest.mark.skipif(s3rver_command() is None, reason="s3rver not installed (bash scripts/setup.sh test)"),
              pytest.mark.slow]  # one conversion: 37 s at a load average of 25

CFG = {"perception": {"backend": "oracle"}, "frames": {"stride": 1}, "export": {"formats": []},
       "physics": {"enabled": False}}


@pytest.fixture()
def s3(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[S3Server]:
    with S3Server(tmp_path / "s3" / "data") as srv:
        for k, v in srv.env.items():
            monkeypatch.setenv(k, v)
        yield srv


def test_converted_scene_on_s3_reads_back_through_its_pointer(s3: S3Server, synthetic_scene, tmp_path: Path,  # noqa: ANN001
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main
    from flows.convert_scene import convert_scene
    from flows.viewer_server import make_viewer_server
    from react3d_core.data.parts import InteractiveScene
    from tasks import storage

    scene = synthetic_scene(seed=3, n_frames=16, kind="dresser")
    scan = s3.url("scans/dresser")  # the scan read from the bucket too, through the scan cache
    fs, path = storage.filesystem(scan)
    fs.pipe({f"{path}/{p.relative_to(scene).as_posix()}": p.read_bytes() for p in scene.rglob("*") if p.is_file()})
    url = s3.url("out/dresser")
    manifest = convert_scene(scan, url, CFG)
    assert manifest == storage.output_manifest(url) and "/v/" in manifest
    copy = storage.fetch_output(url)
    m = InteractiveScene.load(copy / "scene.json")
    assert m.objects and all((copy / o.part_mesh).is_file() for o in m.objects)
    server, _ = make_viewer_server(copy, port=0)
    server.server_close()

    assert main(["export", url, "--to", str(tmp_path / "local"), "--formats", "urdf"]) == 0
    assert "urdf:" in capsys.readouterr().out
    assert list((tmp_path / "local").rglob("*.urdf")) and (tmp_path / "local" / "scene.json").is_file()
