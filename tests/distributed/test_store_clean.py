"""``react3d cache clean --store``: a hand-made store (a local folder, and a bucket on the S3 server when s3rver
is installed) where the dry run lists exactly the unreferenced and expired entries, and the clean removes
only those; files outside react3d's layout are never touched."""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import pytest

from deployments.local_cluster import S3Server


def _sha(tag: str) -> str:
    return hashlib.sha256(tag.encode()).hexdigest()


def _obj(tag: str) -> str:
    s = _sha(tag)
    return f"objects/{s[:2]}/{s}.npz"


def _folder(stage: str, tag: str) -> str:
    h = _sha(tag)[:32]
    return f"scenes/{h[:2]}/{stage}-{h}"


def _record(step: str, tag: str) -> str:
    return f"prefect-results/{step}-{_sha(tag)[:40]}"


def _record_text(*handles: str) -> str:
    """A Prefect result record as react3d's tasks write it: the handle JSON inside the record JSON."""
    result = {"sha256": "x", "path": handles[0], "kind": "k", "more": [{"sha256": "y", "path": h} for h in handles[1:]]}
    return json.dumps({"metadata": {"serializer": {"type": "json"}}, "result": json.dumps(result)})


A, B, C, D, H = (_obj(t) for t in "ABCDH")
E, F, G = _folder("export", "E"), _folder("assembly", "F"), _folder("export", "G")
REC_LIVE, REC_FOLDER, REC_OLD = _record("perception", "1"), _record("export", "2"), _record("segmentation", "3")
REC_OTHER = "prefect-results/33e5ebb640184014b8aa9ee9c7ea9374"  # not a react3d task record: never removed
FOREIGN = ["objects/README.txt", f"objects/{_sha('B')[:2]}/.b.npz.tmp-123", f"objects/zz/{_sha('Z')}.npz",
           "scenes/notes.txt", "mydata/x.csv", f"{E}-copy/scene.json"]

STORE: dict[str, str] = {
    REC_LIVE: _record_text(A), REC_FOLDER: _record_text(f"{E}/scene.json"), REC_OLD: _record_text(C),
    REC_OTHER: _record_text(D),
    A: "a", B: "b", C: "c", D: "d", H: "h",
    f"{E}/scene.json": "{}", f"{E}/m/part.ply": "ply", f"{E}.seal.json": "{}",
    f"{F}/scene.json": "{}", f"{F}/m/deep/part.ply": "ply", f"{F}.seal.json": "{}",
    f"{G}.seal.json": "{}",  # a seal whose folder is gone: in the layout, unreferenced
    **{f: "theirs" for f in FOREIGN},
}
UNREFERENCED = {B, f"{F}/", f"{G}/"}
"""What no record references (H too, but it was written just now: kept by the grace period)."""
EXPIRED = {f"records/{REC_OLD.split('/', 1)[1]}", C}
"""With --older-than 5: the 10-day-old record and the object only it references."""


def _write_local(root: Path) -> None:
    now, two_hours, ten_days = time.time(), time.time() - 7200, time.time() - 10 * 86400
    for rel, text in STORE.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
        t = now if rel == H else ten_days if rel == REC_OLD else two_hours
        os.utime(p, (t, t))


def _listed(out: str) -> set[str]:
    """The store-relative names of the dry run's ``would remove LOCATION (...)`` lines."""
    names = set()
    for line in out.splitlines():
        if line.startswith("would remove "):
            where = line[len("would remove "):].split("  (")[0]
            rel = where.split("/prefect-results/")[1] if "/prefect-results/" in where else None
            names.add(f"records/{rel}" if rel else where[where.index("/objects/") + 1:] if "/objects/" in where
                      else where[where.index("/scenes/") + 1:])
    return names


@pytest.fixture()
def local_store(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    root = tmp_path / "store"
    _write_local(root)
    monkeypatch.setenv("REACT3D_STORE", str(root))
    monkeypatch.delenv("PREFECT_LOCAL_STORAGE_PATH", raising=False)
    return root


def _files(root: Path) -> set[str]:
    return {p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()}


def test_local_store_dry_run_lists_exactly_the_unreferenced_then_clean_removes_only_those(
        local_store: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main

    before = _files(local_store)
    assert main(["cache", "clean", "--store", "--dry-run"]) == 0
    assert _listed(capsys.readouterr().out) == UNREFERENCED
    assert main(["cache", "clean", "--store", "--older-than", "5", "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert _listed(out) == UNREFERENCED | EXPIRED
    assert "5 files not in react3d's layout left alone" in out  # mydata/ is not even listed
    assert _files(local_store) == before  # a dry run removes nothing

    assert main(["cache", "clean", "--store", "--older-than", "5"]) == 0
    gone = {B, C, REC_OLD, f"{F}/scene.json", f"{F}/m/deep/part.ply", f"{F}.seal.json", f"{G}.seal.json"}
    assert _files(local_store) == before - gone
    assert not (local_store / F).exists()  # its empty sub-folders went with it
    assert all((local_store / f).read_text() == "theirs" for f in FOREIGN)

    assert main(["cache", "clean", "--store", "--older-than", "5", "--dry-run"]) == 0  # nothing left to do
    assert _listed(capsys.readouterr().out) == set()


def test_store_clean_refuses_when_no_record_is_found(local_store: Path, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """Records looked for in the wrong place would make every object look unreferenced: nothing goes."""
    from flows.cli import main

    monkeypatch.setenv("PREFECT_LOCAL_STORAGE_PATH", str(tmp_path / "elsewhere"))
    before = _files(local_store)
    assert main(["cache", "clean", "--store"]) == 2
    assert _files(local_store) == before


def test_bucket_store_dry_run_lists_exactly_the_unreferenced_then_clean_removes_only_those(
        s3: S3Server, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main
    from tasks import storage

    for k, v in s3.env.items():
        monkeypatch.setenv(k, v)
    url = s3.url(tmp_path.name)
    monkeypatch.setenv("REACT3D_STORE", url)
    monkeypatch.setenv("REACT3D_CACHE", str(tmp_path / "mirror"))
    fs, root = storage.filesystem(url)
    fs.pipe({f"{root}/{rel}": text.encode() for rel, text in STORE.items()})
    before = {f[len(root) + 1:] for f in fs.find(root)}
    assert before == set(STORE)

    # objects on a bucket cannot be back-dated: --grace 0 counts even the one written just now
    assert main(["cache", "clean", "--store", "--grace", "0", "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert _listed(out) == UNREFERENCED | {H}
    assert all(line.startswith(f"would remove {url}/") for line in out.splitlines() if line.startswith("would"))
    fs.invalidate_cache()
    assert {f[len(root) + 1:] for f in fs.find(root)} == before

    assert main(["cache", "clean", "--store", "--grace", "0"]) == 0
    fs.invalidate_cache()
    gone = {B, H, f"{F}/scene.json", f"{F}/m/deep/part.ply", f"{F}.seal.json", f"{G}.seal.json"}
    assert {f[len(root) + 1:] for f in fs.find(root)} == before - gone


def test_an_object_reused_by_a_running_task_counts_as_recent(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A task that puts an object the store already holds renews its age: the grace period covers it until
    the task's record names it, although no record references it yet."""
    import numpy as np

    from tasks import store, store_clean

    monkeypatch.setenv("REACT3D_STORE", str(tmp_path / "store"))
    monkeypatch.delenv("PREFECT_LOCAL_STORAGE_PATH", raising=False)
    (tmp_path / "store" / "prefect-results").mkdir(parents=True)
    h = store.put({"v": np.arange(3)}, "perception")
    path = tmp_path / "store" / h["path"]
    past = time.time() - 7200
    os.utime(path, (past, past))
    assert [e.rel for e in store_clean.plan_clean().remove] == [h["path"]]
    store.put({"v": np.arange(3)}, "perception")
    assert store_clean.plan_clean().remove == []
