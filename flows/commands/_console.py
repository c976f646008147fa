"""The rich console the commands print to."""

from __future__ import annotations

import os
from typing import Any

from rich.console import Console

LOG_WIDTH = 200


def wide_console(**kwargs: Any) -> Console:
    """A rich console; in a log file or a pipe (no terminal, no COLUMNS set) ``LOG_WIDTH`` columns wide.

    Why: without a terminal rich assumes 80 columns and shrinks a wide table's every cell to an ellipsis,
    so a benchmark or a dataset run written to a log showed no scene name and no number."""
    c = Console(**kwargs)
    if c.is_terminal or os.environ.get("COLUMNS"):
        return c
    return Console(width=LOG_WIDTH, **kwargs)
