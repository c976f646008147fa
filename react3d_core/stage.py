"""Stage descriptors: each stage package says once what it is (version), what it reads (config
sections) and what it builds on (upstream stages).

Everything else is derived from these declarations (``react3d_core.pipeline.stages``): the cache key of
a Prefect task, the config a task is handed, the versions recorded in a manifest, and the check that a
stage reads no config section it did not declare (a section left undeclared would otherwise be left out
of the key, and a changed value would silently reuse a stale result).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class StageSpec:
    """One pipeline stage.

    ``version`` is bumped when the stage's algorithm changes (its output for the same input may differ);
    ``sections`` are the ``PipelineConfig`` sections its code reads; ``upstream`` the stages whose
    output it consumes (their versions and sections are part of this stage's identity too);
    ``parts`` sub-versions recorded beside the version (e.g. one per perception backend)."""

    name: str
    module: str
    version: str
    sections: tuple[str, ...] = ()
    upstream: tuple[str, ...] = ()
    parts: dict[str, str] = field(default_factory=dict)

    def versions(self) -> dict[str, str]:
        """``{module: version}`` for the manifest: the package and each named part."""
        return {self.module: self.version, **self.parts}
