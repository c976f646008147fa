"""Imports point downward only: flows -> tasks -> react3d_core, and none of them imports the benchmark
scripts (``benchmarks/`` is not installed). Read from the source (AST), so a lazy import inside a
function counts as much as one at the top, and so do module paths handed to importlib as strings."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("react3d_core", "tasks", "flows")
FORBIDDEN = {
    "react3d_core": {"tasks", "flows", "benchmarks"},
    "tasks": {"flows", "benchmarks"},
    "flows": {"benchmarks"},
}
_MODULE_PATH = re.compile(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*")


def imported_packages(path: Path) -> set[tuple[int, str]]:
    """(line, top-level package) of every absolute import in ``path`` and of every string constant that
    is a dotted module path of one of the project's packages (``importlib.import_module("flows.x")``)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {(node.lineno, a.name.split(".")[0]) for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.add((node.lineno, node.module.split(".")[0]))
        elif (isinstance(node, ast.Constant) and isinstance(node.value, str) and _MODULE_PATH.fullmatch(node.value)
              and "." in node.value and node.value.split(".")[0] in {*PACKAGES, "benchmarks"}):
            out.add((node.lineno, node.value.split(".")[0]))
    return out


def violations(package: str) -> list[str]:
    bad = []
    for path in sorted((ROOT / package).rglob("*.py")):
        for line, top in sorted(imported_packages(path)):
            if top in FORBIDDEN[package]:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {top}")
    return bad


@pytest.mark.parametrize("package", PACKAGES)
def test_imports_point_downward_and_never_at_the_benchmark_scripts(package: str) -> None:
    assert violations(package) == []


def test_the_walk_sees_lazy_and_string_imports(tmp_path: Path) -> None:
    src = tmp_path / "m.py"
    src.write_text("import os\n\ndef f():\n    from benchmarks.runner import x\n    import tasks.keys\n"
                   "    return importlib.import_module('flows.commands.bench'), 'not a module path', 'flows'\n")
    assert imported_packages(src) == {(1, "os"), (4, "benchmarks"), (5, "tasks"), (6, "flows")}


def test_the_walk_covers_the_packages() -> None:
    """Guards the test itself: the packages are where it looks, and the CLI's command table is seen."""
    assert all(len(list((ROOT / p).rglob("*.py"))) > 5 for p in PACKAGES)
    assert any(top == "flows" for _, top in imported_packages(ROOT / "flows" / "cli.py"))


def test_prefect_artifacts_are_made_in_one_module() -> None:
    """What the Prefect UI shows of a run (progress, summaries, tables, links) is made in flows/artifacts.py."""
    users = set()
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                         else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
                if any(n == "prefect.artifacts" or n.startswith("prefect.artifacts.") for n in names):
                    users.add(path.relative_to(ROOT).as_posix())
    assert users == {"flows/artifacts.py"}


OWN = ("react3d_core", "react3d_models", "tasks", "flows", "benchmarks")


def _own_module_exists(name: str) -> bool:
    parts = name.split(".")
    base = ROOT.joinpath(*parts)
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


@pytest.mark.parametrize("folder", ["benchmarks", "flows", "tasks", "react3d_models", "scripts"])
def test_every_import_of_our_own_modules_resolves(folder: str) -> None:
    """A module that moved leaves no import behind, lazy ones inside functions included (a benchmark
    script run once a release is where such an import would otherwise be found)."""
    missing = []
    for path in sorted((ROOT / folder).rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            for n in names:
                if n.split(".")[0] in OWN and not _own_module_exists(n):
                    missing.append(f"{path.relative_to(ROOT)}:{node.lineno}: {n}")
    assert not missing, "imports of modules that do not exist:\n" + "\n".join(missing)
