"""Cache keys from content, the pickle-free store, retry decisions, OOM batch splitting."""

from __future__ import annotations

import numpy as np
import pytest

from react3d_core.data.masks import ArticulationPrediction, Mask2D
from react3d_core.data.mesh import TriMesh
from react3d_core.errors import InputError
from tasks import serialize, store
from tasks.keys import content_key
from react3d_core.pipeline import split_on_oom
from tasks.retry import TransientError, is_transient


def test_serialize_round_trip_models_dataclasses_arrays() -> None:
    m = Mask2D(frame_id="f1", mask=np.eye(4, dtype=bool), box=(0.0, 0.0, 3.0, 3.0))
    p = ArticulationPrediction(frame_id="f1", mask=np.ones((2, 2), bool), joint_type="revolute", axis_cam=(0.0, 0.0, 1.0))
    mesh = TriMesh(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    obj = {"masks": {"f1": [m]}, "preds": [p], "mesh": mesh, "t": (1, "a"), "n": np.int64(3)}
    back = serialize.loads(serialize.dumps(obj))
    assert back["masks"]["f1"][0].frame_id == "f1" and (back["masks"]["f1"][0].mask == m.mask).all()
    assert back["masks"]["f1"][0].box == (0.0, 0.0, 3.0, 3.0)
    assert back["preds"][0].axis_cam == (0.0, 0.0, 1.0)
    assert (back["mesh"].faces == mesh.faces).all() and back["t"] == (1, "a") and back["n"] == 3


def test_serialize_refuses_foreign_classes() -> None:
    class Foreign:
        pass

    with pytest.raises(TypeError):
        serialize.dumps(Foreign())
    bad = serialize.dumps({"x": 1}).replace(b"x", b"x")  # a valid file still loads
    assert serialize.loads(bad) == {"x": 1}


def test_store_handles_are_content_addressed(tmp_path, monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path))
    a = store.put({"v": np.arange(5)}, "x")
    b = store.put({"v": np.arange(5)}, "x")
    assert a == b and a["path"] == f"objects/{a['sha256'][:2]}/{a['sha256']}.npz"  # relative: no absolute path in records
    assert (store.get(a)["v"] == np.arange(5)).all()
    (tmp_path / "objects" / a["sha256"][:2] / f"{a['sha256']}.npz").unlink()
    with pytest.raises(InputError, match="cache clean"):
        store.get(a)


def test_keys_ignore_paths_and_follow_content_and_version(monkeypatch) -> None:  # noqa: ANN001
    from react3d_core.config import PipelineConfig
    from react3d_core.pipeline import stages
    from react3d_core.stage import StageSpec

    c = PipelineConfig().model_dump(mode="json")
    k = content_key("segmentation")
    h1 = {"sha256": "abc", "path": "/run1/x.npz"}
    h2 = {"sha256": "abc", "path": "/run2/x.npz"}
    c2 = {**c, "fusion": {**c["fusion"], "min_cooccurrence": 99}}
    base = k(None, {"scene_path": "/a", "handle": h1, "config": c})
    assert base == k(None, {"scene_path": "/b", "handle": h2, "config": c})
    assert base != k(None, {"scene_path": "/a", "handle": {"sha256": "abd", "path": "/run1/x.npz"}, "config": c})
    assert base != k(None, {"scene_path": "/a", "handle": h1, "config": c2})
    reg = dict(stages.all_stages())
    reg["fusion"] = StageSpec(**{**reg["fusion"].__dict__, "version": "999"})
    monkeypatch.setattr(stages, "all_stages", lambda: reg)
    assert base != k(None, {"scene_path": "/a", "handle": h1, "config": c})  # a new stage version: a new key


def test_transient_errors() -> None:
    class OutOfMemoryError(RuntimeError):
        pass

    assert is_transient(OutOfMemoryError("CUDA out of memory"))
    assert is_transient(TimeoutError()) and is_transient(TransientError("x"))
    assert not is_transient(InputError("/x", "missing")) and not is_transient(ValueError("bug"))


def test_oom_splits_batches() -> None:
    calls = []

    class OutOfMemoryError(RuntimeError):
        pass

    def fn(frames, images):  # noqa: ANN001, ANN202
        calls.append(len(frames))
        if len(frames) > 2:
            raise OutOfMemoryError("CUDA out of memory")
        return [f * 10 for f in frames]

    assert split_on_oom(fn, [1, 2, 3, 4, 5], [None] * 5) == [10, 20, 30, 40, 50]
    assert calls[0] == 5 and max(calls[1:]) <= 3
    with pytest.raises(ValueError):
        split_on_oom(lambda f, i: (_ for _ in ()).throw(ValueError("bug")), [1, 2], [None] * 2)


def test_openable_phrases_follow_the_paper() -> None:
    from react3d_core.config import PerceptionConfig
    from react3d_core.pipeline import openable_phrases

    assert openable_phrases(["cabinet", "refrigerator"], PerceptionConfig()) == ["cabinet door", "door", "refrigerator door"]
    assert openable_phrases([], PerceptionConfig()) == ["door"]  # 'door' is always kept


def test_cached_selections_round_trip_and_ignore_a_damaged_file(tmp_path, monkeypatch) -> None:  # noqa: ANN001
    from tasks.scene import CachedSelections

    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path))
    memo = CachedSelections()
    assert memo.get("ab" * 32) is None
    memo.put("ab" * 32, {"frame_ids": ["f1", "f3"], "reason": "kept 2 of 3 frames"})
    assert memo.get("ab" * 32) == {"frame_ids": ["f1", "f3"], "reason": "kept 2 of 3 frames"}
    path = tmp_path / "selections" / "ab" / f"{'ab' * 32}.json"
    path.write_text("{not json")
    assert memo.get("ab" * 32) is None  # selected again, never a traceback


def test_decoded_objects_are_kept_within_a_byte_budget(tmp_path, monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path))
    store.clear_decoded()
    mask = np.zeros((1000, 1000), bool)
    obj, size = serialize.loads_sized(serialize.dumps({"m": mask}))
    assert obj["m"].shape == (1000, 1000) and 1_000_000 <= size < 1_001_000  # packed on disk, 1 byte a pixel decoded
    monkeypatch.setattr(store, "DECODED_CACHE_BYTES", 2_500_000)
    handles = [store.put({"m": mask, "i": i}, "x") for i in range(5)]
    for h in handles:
        store.get(h)
    assert store.decoded_cache_bytes() <= 2_500_000
    assert store._decoded and list(store._decoded) == [h["sha256"] for h in handles[-2:]]  # the most recent stay
    assert store.get(handles[-1])["i"] == 4
    store.clear_decoded()
