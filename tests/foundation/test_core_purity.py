"""react3d_core is the pure library (docs/CONTRACTS.md): importing it, or any module in it, must not
import the orchestrator (prefect) or the model stack (torch, transformers, the react3d_models package that
the perception factory imports only when the config names the models backend), which live in tasks/
and in the ``models`` extra. Checked in a fresh interpreter, since this test session may already
have imported them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("prefect", "torch", "transformers", "react3d_models")

_PROBE = r"""
import importlib, json, pkgutil, sys
heavy = %r
found, errors = {}, {}
def check(name):
    for h in heavy:
        if h in sys.modules and h not in found:
            found[h] = name  # the first module after whose import it was loaded
import react3d_core
check("react3d_core")
for m in pkgutil.walk_packages(react3d_core.__path__, "react3d_core."):
    try:
        importlib.import_module(m.name)
    except Exception as exc:  # noqa: BLE001 - reported below
        errors[m.name] = repr(exc)
    check(m.name)
print(json.dumps({"found": found, "errors": errors, "n": len(list(pkgutil.walk_packages(react3d_core.__path__, "react3d_core.")))}))
"""


def test_core_imports_neither_prefect_nor_torch() -> None:
    out = subprocess.run([sys.executable, "-c", _PROBE % (HEAVY,)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["errors"] == {}
    assert res["n"] > 50  # the walk did see the package's modules
    assert res["found"] == {}, f"react3d_core pulls in {res['found']} (module: the first importer)"
