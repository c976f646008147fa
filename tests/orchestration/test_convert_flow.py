"""The convert flows on a real Prefect (test harness): outputs, full cache reuse, resume after a crash,
a transient failure retried, a failed scene isolated in a dataset run."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import tasks.articulation as t_art
import tasks.perception as t_perc
import tasks.physics as t_phys
import tasks.segmentation as t_seg
from flows.convert_dataset import convert_dataset
from flows.convert_scene import convert_scene
from react3d_core.data.parts import InteractiveScene
from tasks.retry import TransientError

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

CFG = {"perception": {"backend": "oracle"}, "frames": {"stride": 1},
       "export": {"formats": ["urdf", "mjcf"]}}


def _counting(monkeypatch, module, name: str) -> list[int]:  # noqa: ANN001
    calls: list[int] = []
    real = getattr(module, name)

    def wrapped(*a, **k):  # noqa: ANN002, ANN003, ANN202
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(module, name, wrapped)
    return calls


@pytest.fixture(scope="module")
def scene(synthetic_scene) -> Path:  # noqa: ANN001
    return synthetic_scene(seed=3, n_frames=16, kind="dresser")


def test_convert_then_everything_cached(scene: Path, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    cfg = {**CFG, "perception": {"backend": "oracle", "oracle": {"seed": 11}}}  # keys unique to this test
    manifest = convert_scene(str(scene), str(tmp_path / "a"), cfg)
    m = InteractiveScene.load(manifest)
    assert m.objects and (tmp_path / "a" / "export" / "urdf" / "scene.urdf").exists()
    assert (tmp_path / "a" / "report.html").exists() and (tmp_path / "a" / "metrics.json").exists()
    assert {"perception", "segmentation", "articulation", "assembly", "export", "total"} <= set(m.timings)
    assert m.config["perception"]["backend"] == "oracle" and "react3d_core.fusion" in m.versions
    # the physics check ran on the export (MuJoCo by default) and is recorded beside it
    assert "physics" in m.timings and m.physics["engines"]["mujoco"]["status"] == "ok"
    assert m.physics["engines"]["mujoco"]["joints"] == len(m.objects)
    assert json.loads((tmp_path / "a" / "physics_check.json").read_text())["scene_id"] == m.scene_id
    counts = [_counting(monkeypatch, mod, fn) for mod, fn in ((t_perc, "perceive_body"), (t_seg, "segment_body"),
                                                             (t_art, "articulate_body"), (t_phys, "check_body"))]
    manifest2 = convert_scene(str(scene), str(tmp_path / "b"), cfg)  # another output folder: same content keys
    assert [len(c) for c in counts] == [0, 0, 0, 0]
    assert InteractiveScene.load(manifest2).physics["engines"] == m.physics["engines"]
    assert len(InteractiveScene.load(manifest2).objects) == len(m.objects)
    # the same scan copied elsewhere hits the same cache, and the result refers to the copy's mesh
    copy = tmp_path / "copy"
    shutil.copytree(scene, copy)
    manifest3 = convert_scene(str(copy), str(tmp_path / "c"), cfg)
    assert [len(c) for c in counts] == [0, 0, 0, 0]
    m3 = InteractiveScene.load(manifest3)
    assert (Path(manifest3).parent / m3.input_mesh).resolve() == (copy / "scans" / "mesh_aligned_0.05.ply").resolve()


def test_resume_after_crash(scene: Path, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    cfg = {**CFG, "perception": {"backend": "oracle", "oracle": {"seed": 12}}}
    import react3d_core.assembly as asm

    real = asm.assemble_scene

    def crash(*a, **k):  # noqa: ANN002, ANN003, ANN202
        raise RuntimeError("simulated crash in assembly")

    monkeypatch.setattr(asm, "assemble_scene", crash)
    with pytest.raises(RuntimeError, match="simulated crash"):
        convert_scene(str(scene), str(tmp_path / "out"), cfg)
    assert not (tmp_path / "out").exists()  # nothing half-written
    monkeypatch.setattr(asm, "assemble_scene", real)
    counts = [_counting(monkeypatch, t_perc, "perceive_body"), _counting(monkeypatch, t_seg, "segment_body")]
    manifest = convert_scene(str(scene), str(tmp_path / "out"), cfg)
    assert [len(c) for c in counts] == [0, 0]  # resumed from the cached tasks
    clean = convert_scene(str(scene), str(tmp_path / "clean"), cfg)
    a, b = json.loads(Path(manifest).read_text()), json.loads(Path(clean).read_text())
    assert [o["articulation"] for o in a["objects"]] == [o["articulation"] for o in b["objects"]]


def test_transient_failure_is_retried(scene: Path, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    cfg = {**CFG, "perception": {"backend": "oracle", "oracle": {"seed": 13}}}
    real = t_perc.perceive_body
    failed: list[int] = []

    def flaky(*a, **k):  # noqa: ANN002, ANN003, ANN202
        if not failed:
            failed.append(1)
            raise TransientError("endpoint timed out")
        return real(*a, **k)

    monkeypatch.setattr(t_perc, "perceive_body", flaky)
    assert Path(convert_scene(str(scene), str(tmp_path / "o"), cfg)).exists()
    assert failed == [1]


def test_dataset_run_isolates_a_corrupt_scene(scene: Path, tmp_path: Path) -> None:
    root = tmp_path / "data"
    shutil.copytree(scene, root / "good")
    shutil.copytree(scene, root / "broken")
    (root / "broken" / "scans" / "mesh_aligned_0.05.ply").write_bytes(b"ply\nformat ascii 1.0\nelement vertex 3\n")
    rows = convert_dataset(str(root), out_root=str(tmp_path / "out"), config=CFG)
    by = {r["scene"]: r for r in rows}
    assert by["good"]["status"] == "ok" and by["good"]["parts"] > 0
    assert by["broken"]["status"] == "failed" and "mesh_aligned_0.05.ply" in by["broken"]["error"]


def test_cold_cache_recomputes_and_leaves_a_self_contained_result(scene: Path, tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    from flows.bench.runner import cold_cache
    from tasks.store import cache_root

    cfg = {**CFG, "perception": {"backend": "oracle", "oracle": {"seed": 14}}, "export": {"formats": []}}
    convert_scene(str(scene), str(tmp_path / "warm"), cfg)
    warm_store = cache_root()
    counts = [_counting(monkeypatch, mod, fn) for mod, fn in ((t_perc, "perceive_body"), (t_seg, "segment_body"))]
    with cold_cache(tmp_path / "cold") as root:
        assert cache_root() == root / "react3d"
        manifest = convert_scene(str(scene), str(tmp_path / "out"), cfg)
        assert any((root / "react3d" / "objects").rglob("*.npz"))
    assert [len(c) for c in counts] == [2, 1]  # 16 frames = 2 batches: a warm cache held them; the cold run recomputed
    assert not root.exists() and not any((tmp_path / "cold").iterdir()) and cache_root() == warm_store
    m = InteractiveScene.load(manifest)  # the published result does not point into the deleted cache
    assert m.objects and all((Path(manifest).parent / o.part_mesh).is_file() for o in m.objects)


def test_a_completed_scan_in_the_cache_is_copied_into_the_result(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    """A scan this program completed (slabs over surfaces the sensor missed) lives in the cache; the
    published result keeps its own copy, so pruning the cache (or a benchmark's cold cache going) leaves
    it whole. A scan outside the cache stays where it is, referred to relatively."""
    from react3d_core.data.parts import InteractiveScene
    from tasks.assembly import COMPLETED_SCAN, fill_output
    from tasks.store import cache_root

    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "cache"))
    src = cache_root() / "scenes" / "ab" / "assemble-x"
    src.mkdir(parents=True)
    InteractiveScene(scene_id="s", input_mesh="unused.ply", background_mesh="bg.ply").save(src / "scene.json")
    (src / "bg.ply").write_bytes(b"background")
    completed = cache_root() / "missed_surface" / "ab" / "abc.ply"
    completed.parent.mkdir(parents=True)
    completed.write_bytes(b"completed scan")
    result = {"path": str((src / "scene.json").relative_to(cache_root()))}
    out = tmp_path / "out"
    manifest = Path(fill_output(result, tmp_path / ".out-staging", out, str(completed)))
    m = InteractiveScene.load(manifest)
    assert m.input_mesh == COMPLETED_SCAN and (manifest.parent / COMPLETED_SCAN).read_bytes() == b"completed scan"
    scan = tmp_path / "scan" / "mesh.ply"
    scan.parent.mkdir()
    scan.write_bytes(b"the user's scan")
    manifest = Path(fill_output(result, tmp_path / ".out-staging2", out, str(scan)))
    assert InteractiveScene.load(manifest).input_mesh == "../scan/mesh.ply"
    assert not (manifest.parent / COMPLETED_SCAN).exists()
