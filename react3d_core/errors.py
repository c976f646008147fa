"""Errors users see. Every bad-input error names the file and the problem in one line."""

from __future__ import annotations

from pathlib import Path


class React3DError(Exception):
    """Base class of all errors raised on purpose by REACT3D."""


class InputError(React3DError):
    """Bad input: a missing/corrupt file or an invalid value, reported as ``<path>: <problem>``."""

    def __init__(self, path: str | Path | None, problem: str) -> None:
        self.path = None if path is None else Path(path)
        self.problem = problem
        super().__init__(f"{path}: {problem}" if path is not None else problem)

    def __reduce__(self) -> tuple[type, tuple[Path | None, str]]:
        """Rebuilt from (path, problem) when it crosses a process boundary (a benchmark's scene worker):
        the default rebuilds from the message alone and failed, leaving the parent waiting for ever."""
        return type(self), (self.path, self.problem)


class ConfigError(React3DError):
    """Invalid pipeline configuration (unknown backend, out-of-range threshold, ...)."""


class StageError(React3DError):
    """A stage could not produce its output (e.g. no frames see the mesh)."""
