"""Array files are read without numpy's ast-based header parser, and read back exactly."""

from __future__ import annotations

import ast
import io
import struct
import threading
from pathlib import Path

import numpy as np
import pytest

from react3d_core.npyio import load_npy, load_npz, read_npy_stream
from tasks.serialize import dumps, loads


@pytest.fixture
def no_ast(monkeypatch):  # noqa: ANN001, ANN201
    """Any call into ast.literal_eval fails the test: numpy's loader would make one per array."""

    def boom(*a, **k):  # noqa: ANN002, ANN003, ANN202
        raise AssertionError("ast.literal_eval called")

    monkeypatch.setattr(ast, "literal_eval", boom)
    monkeypatch.setattr(np.lib.format, "safe_eval", boom, raising=False)


ARRAYS = {
    "u16": np.arange(12, dtype=np.uint16).reshape(3, 4),
    "f4_be": np.linspace(0, 1, 6).astype(">f4").reshape(2, 3),
    "fortran": np.asfortranarray(np.arange(6, dtype=np.int64).reshape(2, 3)),
    "scalar": np.array(3.5),
    "empty": np.zeros((0, 5), dtype=np.float32),
    "bool": np.array([True, False, True]),
    "text": np.array(["door", "drawer"]),
}


def test_npz_round_trip_without_ast(tmp_path: Path, no_ast) -> None:  # noqa: ANN001
    p = tmp_path / "a.npz"
    np.savez_compressed(p, **ARRAYS)
    got = load_npz(p)
    assert sorted(got) == sorted(ARRAYS)
    for k, a in ARRAYS.items():
        assert got[k].dtype == a.dtype and got[k].shape == a.shape, k
        np.testing.assert_array_equal(got[k], a)
    assert got["fortran"].flags.f_contiguous
    got["u16"][0, 0] = 7  # writable like np.load's arrays
    assert load_npz(p.read_bytes())["u16"][0, 0] == 0


def test_npy_file_and_hand_written_header(tmp_path: Path, no_ast) -> None:  # noqa: ANN001
    p = tmp_path / "d.npy"
    np.save(p, np.full((2, 2), 1.25, dtype=np.float32))
    np.testing.assert_array_equal(load_npy(p), np.full((2, 2), 1.25, dtype=np.float32))
    # version 2.0 header with the keys in another order, written by hand
    header = b"{'shape': (3,), 'fortran_order': False, 'descr': '<i2'}"
    header += b" " * (-(12 + len(header) + 1) % 64) + b"\n"
    raw = b"\x93NUMPY\x02\x00" + struct.pack("<I", len(header)) + header + struct.pack("<3h", -1, 0, 300)
    assert read_npy_stream(io.BytesIO(raw)).tolist() == [-1, 0, 300]


def _v1(header: bytes, data: bytes = b"") -> bytes:
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + data


@pytest.mark.parametrize(("raw", "msg"), [
    (b"PK\x03\x04junk", "bad magic"),
    (_v1(b"{'descr': '|O', 'fortran_order': False, 'shape': (1,), }\n"), "object arrays"),
    (_v1(b"{'descr': [('a', '<f4')], 'shape': (1,)}\n"), "unsupported .npy header"),
    (_v1(b"{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }\n", b"\0" * 16), "truncated .npy data: 16 of 32"),
])
def test_bad_arrays_are_refused_with_a_reason(raw: bytes, msg: str) -> None:
    with pytest.raises(ValueError, match=msg):
        read_npy_stream(io.BytesIO(raw))


def test_cached_results_decode_from_many_threads(no_ast) -> None:  # noqa: ANN001
    blob = dumps({"mask": np.eye(64, dtype=bool), "depth": np.arange(4096, dtype=np.float32)})
    errors: list[BaseException] = []

    def work() -> None:
        try:
            for _ in range(20):
                out = loads(blob)
                assert out["mask"].sum() == 64 and out["depth"][-1] == 4095
        except BaseException as exc:  # noqa: BLE001 - collected and re-raised below
            errors.append(exc)

    threads = [threading.Thread(target=work) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors[0]
