"""A forged Prefect result record in the shared storage must never run code.

Prefect 3 decodes a record with the serializer the record itself names. These tests forge records the
way an attacker with write access to ``$PREFECT_HOME/storage`` would (``serializer: pickle``, JSON with
``jsonlib: pickle``, JSON with ``object_decoder: subprocess.Popen``), each carrying a payload that
creates a marker file when decoded, and run a
real ``react3d convert`` process on a real Prefect server over them.
"""

from __future__ import annotations

import base64
import json
import pickle
import time
from pathlib import Path

import pytest

from .conftest import convert_oracle_urdf as convert, copy_first_run

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)


class _Touch:
    """Unpickling this object creates ``path`` (a stand-in for any code an attacker would run)."""

    def __init__(self, path: Path) -> None:
        self.path = str(path)

    def __reduce__(self):  # noqa: ANN204 - pickle protocol
        return (open, (self.path, "w"))


def _pickle_record(marker: Path) -> dict:
    payload = base64.b64encode(pickle.dumps(_Touch(marker))).decode()
    return {"metadata": {"storage_key": None, "expiration": None,
                         "serializer": {"type": "pickle", "picklelib": "cloudpickle", "picklelib_version": None},
                         "prefect_version": "3.8.8", "storage_block_id": None},
            "result": payload}


def _json_pickle_record(marker: Path) -> dict:
    """Type 'json' but ``jsonlib: pickle``: a check of the serializer's type alone would let this run."""
    return {"metadata": {"storage_key": None, "expiration": None,
                         "serializer": {"type": "json", "jsonlib": "pickle", "object_encoder": None,
                                        "object_decoder": None, "dumps_kwargs": {}, "loads_kwargs": {}},
                         "prefect_version": "3.8.8", "storage_block_id": None},
            "result": pickle.dumps(_Touch(marker), protocol=0).decode("latin-1")}


def _object_hook_record(marker: Path) -> dict:
    """A valid JSON payload whose ``object_decoder`` is ``subprocess.Popen``: json.loads calls it with the
    payload dict, Popen runs its keys as a command line. Only the serializer allow-list stops this one."""
    return {"metadata": {"storage_key": None, "expiration": None,
                         "serializer": {"type": "json", "jsonlib": "json", "object_encoder": None,
                                        "object_decoder": "subprocess.Popen", "dumps_kwargs": {}, "loads_kwargs": {}},
                         "prefect_version": "3.8.8", "storage_block_id": None},
            "result": json.dumps({"touch": 0, str(marker): 0})}


FORGERIES = (_pickle_record, _json_pickle_record, _object_hook_record)


# --- the check itself, on the bytes Prefect would decode ------------------------------------------------

def _real_json_record(result: object) -> bytes:
    from prefect._internal.result_records import ResultRecord, ResultRecordMetadata
    from prefect.serializers import JSONSerializer

    return ResultRecord(metadata=ResultRecordMetadata(serializer=JSONSerializer()), result=result).serialize()


def test_json_records_written_by_prefect_pass_the_check() -> None:
    from tasks.prefect_env import check_record_bytes

    handle = {"sha256": "ab" * 32, "path": "/x/ab.npz", "kind": "perception", "seconds": 1.5, "frame_ids": ["f1"]}
    assert check_record_bytes(_real_json_record(handle)) == handle


@pytest.mark.parametrize("forge", [
    lambda m: _pickle_record(m),
    lambda m: _json_pickle_record(m),
    lambda m: {**_pickle_record(m), "metadata": {**_pickle_record(m)["metadata"],
                                                 "serializer": {"type": "compressed/pickle", "compressionlib": "lzma",
                                                                "serializer": {"type": "pickle"}}}},
    lambda m: {"data": _pickle_record(m)["result"], "serializer": {"type": "pickle"}},  # legacy layout
    lambda m: _object_hook_record(m),
    lambda m: {"metadata": json.loads(_real_json_record(0))["metadata"],
               "result": json.dumps({"__class__": "subprocess.Popen", "data": ["touch", str(m)]})},
    lambda m: base64.b64encode(pickle.dumps(_Touch(m))).decode(),  # not a record: Prefect would try its backup serializer
], ids=["pickle", "json-with-pickle-lib", "compressed-pickle", "legacy", "json-object-hook-popen", "foreign-class", "bare-pickle"])
def test_forged_records_are_refused_before_decoding(tmp_path: Path, forge) -> None:  # noqa: ANN001
    from prefect._internal.result_records import ResultRecord

    from tasks.prefect_env import UntrustedRecordError, guard_result_records

    guard_result_records()
    marker = tmp_path / "pwned"
    data = json.dumps(forge(marker)).encode()
    with pytest.raises(UntrustedRecordError):
        ResultRecord.deserialize(data)
    forged = forge(marker)
    if isinstance(forged, dict):  # the same record split into metadata + result (a metadata_storage layout)
        with pytest.raises(UntrustedRecordError):
            ResultRecord.deserialize_from_result_and_metadata(
                str(forged.get("result", forged.get("data"))).encode(), json.dumps(forged.get("metadata", forged)).encode())
    time.sleep(0.5)  # a command started by a forged record would have run by now
    assert not marker.exists()


# --- a real convert over a forged storage ---------------------------------------------------------------

def test_forged_records_in_shared_storage_do_not_run(synthetic_scene, dresser_first_run: Path, prefect_server,  # noqa: ANN001
                                                     tmp_path: Path) -> None:
    scene = synthetic_scene(seed=5, n_frames=12, kind="dresser")
    env = copy_first_run(dresser_first_run, tmp_path / "home", tmp_path / "a", prefect_server.home)  # first run: done
    storage = Path(env["PREFECT_LOCAL_STORAGE_PATH"])
    records = sorted(p for p in storage.iterdir() if p.is_file() and p.name.split("-")[0] in
                     {"perception", "segmentation", "articulation", "assembly", "export"})
    assert {p.name.split("-")[0] for p in records} >= {"perception", "segmentation", "export"}
    markers = []
    for i, rec in enumerate(records):  # every cached stage's record forged, cycling through the tricks
        marker = tmp_path / f"pwned-{i}"
        markers.append(marker)
        rec.write_text(json.dumps(FORGERIES[i % len(FORGERIES)](marker)))

    second = convert(scene, tmp_path / "b", env)

    time.sleep(0.5)
    assert [m.name for m in markers if m.exists()] == []  # nothing ran
    assert second.returncode == 0, second.stderr[-3000:]  # ... and the convert recomputed
    assert "ignored a cached Prefect result record" in second.stderr
    a = json.loads((tmp_path / "a" / "scene.json").read_text())
    b = json.loads((tmp_path / "b" / "scene.json").read_text())
    assert [o["articulation"] for o in a["objects"]] == [o["articulation"] for o in b["objects"]]
    # the records run 2 looked up were replaced by the recomputation's JSON records: perception's keys
    # depend only on the scan and config, so all of those; downstream keys hash upstream results and may
    # name other records if a recomputed stage is not bit-identical (the old ones are then never read)
    for rec in records:
        meta = json.loads(rec.read_text())["metadata"]
        if rec.name.startswith("perception-"):
            assert meta["serializer"]["type"] == "json" and meta["serializer"]["jsonlib"] == "json", rec.name
