"""`react3d inspect`: table on a good scene, one error line and exit != 0 on bad input, nothing written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from flows.commands.inspect import summarize
from tests.foundation.test_load_scene import make_iphone


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "flows.cli", "inspect", *args], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[2])


def _files(root: Path) -> set[Path]:
    return {p for p in root.rglob("*")}


def test_summary_numbers(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "s")
    rows, problems = dict(summarize(str(root))[0]), summarize(str(root))[1]
    assert problems == []
    assert rows["frames"] == "4" and rows["RGB resolution"] == "96x72" and rows["depth resolution"] == "256x192"
    assert rows["depth coverage"].startswith("100.0%")
    assert rows["mesh"] == "3 vertices, 1 faces"
    assert rows["bounds (m)"] == "[0.00 0.00 0.00] .. [1.00 1.00 1.00]"


def test_cli_ok_and_bad(tmp_path: Path) -> None:
    root = make_iphone(tmp_path / "s")
    r = _cli(str(root))
    assert r.returncode == 0, r.stderr
    assert "scannetpp_iphone" in r.stdout
    meta = root / "iphone" / "pose_intrinsic_imu.json"
    m = json.loads(meta.read_text())
    m["frame_000002"]["aligned_pose"] = np.full((4, 4), np.inf).tolist()
    meta.write_text(json.dumps(m))
    before = _files(tmp_path)
    r = _cli(str(root))
    assert r.returncode != 0
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "frame_000002" in lines[0] and "NaN or inf" in lines[0]
    assert _files(tmp_path) == before
    r = _cli(str(tmp_path / "missing"))
    assert r.returncode != 0 and len(r.stderr.strip().splitlines()) == 1
