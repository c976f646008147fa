"""Task around :func:`react3d_core.pipeline.finalize`: record the run's config, stage versions and timings
in the manifest being staged."""

from __future__ import annotations

from typing import Any

from prefect import task

from react3d_core.pipeline import finalize as finalize_step


def finalize_body(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    finalize_step(manifest_path, config, versions, timings)
    return manifest_path


@task(name="finalize-manifest", persist_result=False)
def finalize(manifest_path: str, config: dict[str, Any], versions: dict[str, str], timings: dict[str, float]) -> str:
    return finalize_body(manifest_path, config, versions, timings)
