"""Exit 0 when every package that ``pip install -e '.[EXTRAS]'`` would install is already present at a
version the project accepts (and react3d itself is installed); else print what is missing and exit 1.

Usage: python scripts/installed.py [EXTRAS]   e.g. test or sim,models. Reads pyproject.toml only; it
imports nothing of the packages it checks, so it takes a fraction of a second (pip's own check resolves
the whole tree: tens of seconds).
"""

from __future__ import annotations

import importlib.metadata as md
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def missing(extras: list[str]) -> list[str]:
    """Requirements of the project (with ``extras``) that the installed distributions do not meet."""
    try:
        from packaging.requirements import Requirement
    except ImportError:
        return ["packaging (needed to compare versions)"]
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    reqs = list(project["dependencies"])
    for extra in extras:
        reqs += project.get("optional-dependencies", {}).get(extra, [])
    out = []
    try:
        if md.version(project["name"]) != project["version"]:
            out.append(f"{project['name']}=={project['version']} (this project)")
    except md.PackageNotFoundError:
        out.append(f"{project['name']} (this project)")
    for text in reqs:
        req = Requirement(text)
        if req.marker is not None and not req.marker.evaluate():
            continue
        try:
            version = md.version(req.name)
        except md.PackageNotFoundError:
            out.append(text)
            continue
        if not req.specifier.contains(version, prereleases=True):
            out.append(f"{text} (found {version})")
    return out


def main(argv: list[str]) -> int:
    extras = [e for e in (argv[0].split(",") if argv else []) if e]
    gaps = missing(extras)
    for g in gaps:
        print(f"[setup] missing: {g}")
    return 1 if gaps else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
