"""The rich console the commands print to."""

from __future__ import annotations

from typing import Any

from rich.console import Console

LOG_WIDTH = 200


def wide_console(**kwargs: Any) -> Console:
    """A rich console; in a log file or a pipe (no terminal) ``LOG_WIDTH`` columns wide.

    Why: without a terminal rich takes 80 columns (or ``COLUMNS``, which CI shells and pytest-xdist workers
    export as 80) and shrinks a wide table's every cell to an ellipsis, so a benchmark or a dataset run
    written to a log showed no scene name and no number. A terminal keeps its own width."""
    c = Console(**kwargs)
    return c if c.is_terminal else Console(width=LOG_WIDTH, **kwargs)
