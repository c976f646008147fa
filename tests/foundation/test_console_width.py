"""Tables the commands print stay readable in a log file or a pipe."""

from __future__ import annotations

import io

import pytest
from rich.table import Table

from flows.commands._console import LOG_WIDTH, wide_console


def _table() -> Table:
    t = Table(title="react3d bench")
    for name in ("scene", "GT", "predicted", "found", "false", "wall s", "peak MB", "F1@0.25", "F1@0.5", "acc %",
                 "MD m", "OE deg", "+MOD %"):
        t.add_column(name)
    t.add_row("scene-synthesizer_any_7001_tsdf", *[f"{k}.123" for k in range(12)])
    return t


def test_a_log_gets_the_whole_table(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("COLUMNS", raising=False)
    out = io.StringIO()
    c = wide_console(file=out)
    assert c.width == LOG_WIDTH
    c.print(_table())
    text = out.getvalue()
    assert "scene-synthesizer_any_7001_tsdf" in text and "11.123" in text and "…" not in text


def test_an_exported_80_columns_does_not_narrow_a_log(monkeypatch: pytest.MonkeyPatch) -> None:
    # CI shells and pytest-xdist workers export COLUMNS=80 while writing to a log
    monkeypatch.setenv("COLUMNS", "80")
    out = io.StringIO()
    c = wide_console(file=out)
    assert c.width == LOG_WIDTH
    c.print(_table())
    assert "…" not in out.getvalue()
    # rich's own console is what the helper replaces: 80 columns cut the cells
    from rich.console import Console

    narrow = io.StringIO()
    Console(file=narrow).print(_table())
    assert "…" in narrow.getvalue()
