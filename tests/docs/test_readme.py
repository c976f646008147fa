"""The README stays a short page for users, and the docs and stored results stay consistent.

The README is the page a new user reads first: it must keep the two commands, how to convert their own
scan (layouts and conventions), what comes out, the current results and the limits, in at most 200
lines. History belongs in docs/changelog.md, not in the README or the reference docs.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"
DOCS = REPO / "docs"
RESULTS = REPO / "benchmarks" / "results"
MAX_README_LINES = 200

# (what a new user looks for, a word of the '## ' heading that holds it)
REQUIRED_SECTIONS = [
    ("install and the two commands", "install"),
    ("converting their own scan", "own scan"),
    ("the react3d commands", "commands"),
    ("the output folder", "comes out"),
    ("current results", "results"),
    ("where it fails", "limits"),
]

# Development-history talk: it goes to docs/changelog.md.
HISTORY = re.compile(r"\bversions? \d+\b|previous release|this release|last release|earlier release|\bissues? #?\d+"
                     r"|(?<![\w&/])#\d+\b", re.IGNORECASE)
# docs/server.md is being rewritten elsewhere; drop it from here once it holds no history either.
HISTORY_EXEMPT = {"changelog.md"}


def _sections(text: str) -> dict[str, str]:
    """'## ' heading (lower case) -> the text under it."""
    out: dict[str, str] = {}
    current = None
    for line in text.splitlines():
        if line.startswith("## "):
            current = line[3:].strip().lower()
            out[current] = ""
        elif current is not None:
            out[current] += line + "\n"
    return out


def _section(sections: dict[str, str], word: str) -> str:
    if word in sections:  # an exact heading first ('commands', not 'install and the two commands')
        return sections[word]
    hits = [body for head, body in sections.items() if word in head]
    assert hits, f"README has no '## ' section whose heading contains {word!r} (headings: {list(sections)})"
    return hits[0]


def test_readme_is_at_most_200_lines() -> None:
    n = len(README.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_README_LINES, f"README.md has {n} lines (at most {MAX_README_LINES}): move detail to docs/"


@pytest.mark.parametrize(("what", "word"), REQUIRED_SECTIONS, ids=[w for w, _ in REQUIRED_SECTIONS])
def test_readme_has_the_sections_a_new_user_needs(what: str, word: str) -> None:
    _section(_sections(README.read_text(encoding="utf-8")), word)


def test_readme_install_section_holds_the_two_commands() -> None:
    body = _section(_sections(README.read_text(encoding="utf-8")), "install")
    for cmd in ("bash scripts/demo.sh", "bash scripts/test.sh"):
        assert cmd in body, f"the install section lost {cmd!r}"
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    assert "bash scripts/test.sh" in ci, "CI no longer runs the README's test command"


def test_readme_own_scan_section_names_layouts_and_conventions() -> None:
    body = _section(_sections(README.read_text(encoding="utf-8")), "own scan")
    for needle in ("ScanNet++ iPhone", "ScanNet++ DSLR", "prepared", "transforms.json", "metres", "z up",
                   "camera-to-world", "OpenCV", "react3d convert", "react3d inspect"):
        assert needle in body, f"the own-scan section no longer says {needle!r}"


def test_readme_commands_are_the_cli_commands() -> None:
    """Every `react3d X` sub-command exists, and every sub-command is listed."""
    from flows.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    real = set(sub.choices)
    body = _section(_sections(README.read_text(encoding="utf-8")), "commands")
    listed = set(re.findall(r"^react3d ([a-z][a-z-]*)", body, flags=re.MULTILINE))
    assert listed == real, f"README lists {sorted(listed)}, the CLI has {sorted(real)}"


def test_readme_and_docs_hold_no_development_history() -> None:
    found = []
    for path in [README, *sorted(DOCS.glob("*.md"))]:
        if path.name in HISTORY_EXEMPT:
            continue
        for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for m in HISTORY.finditer(line):
                found.append(f"{path.relative_to(REPO)}:{i}: {m.group(0)!r}")
    assert not found, "history talk belongs in docs/changelog.md:\n" + "\n".join(found)


def test_history_pattern_catches_what_it_should() -> None:
    for text in ("heuristic version 14", "versions 6-11", "the previous release", "issue 18", "issues 3, 6", "(#15)"):
        assert HISTORY.search(text), text
    for text in ("Python 3.11", "OPDMulti-like 7°", "a `#` comment", "colour #ff0000", "STAGE_VERSION 2", "page#2"):
        assert not HISTORY.search(text), text


def test_docs_named_in_readme_exist() -> None:
    text = README.read_text(encoding="utf-8")
    for name in set(re.findall(r"docs/[\w./-]+\.(?:md|jpg|png)", text)):
        assert (REPO / name).is_file(), f"README names {name}, which does not exist"


def test_results_readme_lists_exactly_the_stored_results() -> None:
    listed = set(re.findall(r"`([\w.-]+\.(?:json|txt))`", (RESULTS / "README.md").read_text(encoding="utf-8")))
    stored = {p.name for p in RESULTS.iterdir() if p.is_file() and p.name != "README.md"}
    assert stored - listed == set(), f"benchmarks/results/README.md does not describe {sorted(stored - listed)}"
    assert listed - stored == set(), f"benchmarks/results/README.md describes missing files {sorted(listed - stored)}"


# Names in docs/results.md that are not stored results (commands' outputs, a scan's own files).
NOT_RESULTS = {"o.json", "onr.json", "h.json", "hnr.json", "metrics.json", "scene.json", "transforms.json"}


def test_result_files_quoted_in_results_and_docs_exist() -> None:
    missing = []
    for path in [README, *sorted(DOCS.glob("*.md"))]:
        if path.name == "changelog.md":  # it quotes removed files by their old names, from the git history
            continue
        text = path.read_text(encoding="utf-8")
        names = set(re.findall(r"benchmarks/results/([\w.-]+\.(?:json|txt))", text))
        if path.name == "results.md":
            names |= {n for n in re.findall(r"`([\w.-]+\.(?:json|txt))`", text)} - NOT_RESULTS
        missing += [f"{path.name}: {n}" for n in sorted(names) if not (RESULTS / n).is_file()]
    assert not missing, "quoted result files that are not in benchmarks/results/:\n" + "\n".join(missing)


CODE_DIRS = ("react3d_core", "react3d_models", "tasks", "flows", "benchmarks", "scripts", "tests", "deployments")
ISSUE_REF = re.compile(r"\bissues? #?\d+|\(#\d+\)", re.IGNORECASE)


def test_code_comments_do_not_name_issues() -> None:
    """Comments and docstrings say why, not which issue: the history is in docs/changelog.md and git."""
    found = []
    for d in CODE_DIRS:
        for path in sorted((REPO / d).rglob("*")):
            if path.suffix not in {".py", ".sh", ".json", ".toml", ".yml", ".yaml"} or path == Path(__file__):
                continue
            if "results" in path.relative_to(REPO).parts[:2]:  # stored benchmark outputs quote their own runs
                continue
            for i, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
                if ISSUE_REF.search(line):
                    found.append(f"{path.relative_to(REPO)}:{i}: {line.strip()[:100]}")
    assert not found, "issue numbers in code:\n" + "\n".join(found)
