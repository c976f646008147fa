"""Prefect artifacts: what the Prefect UI shows of a run (records on the server, not files). A scene's
progress, its summary in markdown and the link to its ``report.html`` (written by
``react3d_core.viewer.report``); a dataset's progress and its one-row-per-scene table. Every artifact
is made here, and each is a no-op outside a flow run: a conversion never fails over the UI."""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from react3d_core.data.parts import InteractiveScene


def _key(s: str) -> str:
    """Artifact keys: lowercase letters, digits and dashes only."""
    return re.sub(r"[^a-z0-9-]+", "-", s.lower()).strip("-")[:60] or "scene"


def create_progress(description: str) -> Any | None:
    """A progress artifact at 0 %, or None outside a flow run (tests of a body, plain calls)."""
    try:
        from prefect.artifacts import create_progress_artifact

        return create_progress_artifact(0.0, description=description)
    except Exception:  # noqa: BLE001 - outside a flow run there is nothing to update
        return None


def set_progress(artifact: Any | None, percent: float) -> None:
    """Move a progress artifact of :func:`create_progress` to ``percent`` (nothing for None)."""
    if artifact is None:
        return
    try:
        from prefect.artifacts import update_progress_artifact

        update_progress_artifact(artifact, percent)
    except Exception:  # noqa: BLE001 - progress is cosmetic; never fail a conversion over it
        pass


class Progress:
    """A ``progress(stage, done, total)`` callback (``react3d_core.pipeline.ProgressFn``) that forwards to
    an optional hook (the CLI's bar) and updates a Prefect progress artifact for the UI.

    The artifact is updated when a stage completes and otherwise at most every ``min_interval_s``: each
    update is an API request, and one per part and frame batch cost a cached conversion 1.3 s."""

    STAGES = ("perception", "segmentation", "articulation", "assembly", "export", "physics", "report")

    def __init__(self, hook: Callable[[str, int, int], None] | None, min_interval_s: float = 2.0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.hook = hook
        self.min_interval_s, self.clock = min_interval_s, clock
        self._last = -float("inf")
        self.updates = 0
        self._artifact = create_progress("REACT3D scene conversion")

    def __call__(self, stage: str, done: int, total: int) -> None:
        if self.hook:
            self.hook(stage, done, total)
        if self._artifact is not None and done:
            now = self.clock()
            if done < total and now - self._last < self.min_interval_s:
                return
            self._last = now
            self._update(stage, done, total)

    def _update(self, stage: str, done: int, total: int) -> None:
        self.updates += 1
        idx = self.STAGES.index(stage) if stage in self.STAGES else 0
        frac = (idx + done / max(total, 1)) / len(self.STAGES)
        set_progress(self._artifact, min(100.0, 100.0 * frac))


def scene_summary_markdown(scene_id: str, manifest_path: str, html: str | None, timings: dict[str, float],
                           metrics: dict[str, Any] | None, n_candidates: int = 0, n_rejected: int = 0) -> str:
    m = InteractiveScene.load(manifest_path)
    lines = [f"# {scene_id}", "", f"Manifest: `{manifest_path}`", ""]
    if html:
        lines += [f"Report: [{html}](file://{Path(html).resolve()})", ""]
    types: dict[str, int] = {}
    for o in m.objects:
        types[o.articulation.joint_type] = types.get(o.articulation.joint_type, 0) + 1
    lines += [f"Parts: **{len(m.objects)}** ({', '.join(f'{v} {k}' for k, v in sorted(types.items())) or 'none'}); "
              f"candidates {n_candidates}, rejected by validation {n_rejected}", "",
              "| part | type | axis | limits | cavity (m) |", "|---|---|---|---|---|"]
    for o in m.objects:
        a = o.articulation
        lines.append(f"| {o.object_id} | {a.joint_type} | {tuple(round(x, 2) for x in a.axis)} | "
                     f"[{a.lower:.2f}, {a.upper:.2f}] | {o.cavity_depth if o.cavity_depth is None else round(o.cavity_depth, 3)} |")
    lines += ["", "| stage | seconds |", "|---|---|"] + [f"| {k} | {v:.2f} |" for k, v in timings.items()]
    if metrics and "aggregate" in metrics:
        lines += ["", "| τ | precision | recall | F1 | joint acc | OE (°) | MD (m) |", "|---|---|---|---|---|---|---|"]
        for tau, r in metrics["aggregate"].items():
            f = lambda x: "–" if x is None else f"{x:.3f}"  # noqa: E731
            lines.append(f"| {tau} | {f(r['precision'])} | {f(r['recall'])} | {f(r['f1'])} | {f(r['joint_acc'])} | {f(r['oe'])} | {f(r['md'])} |")
    return "\n".join(lines)


def publish_scene_artifacts(scene_id: str, manifest_path: str, html: str | None, timings: dict[str, float],
                            metrics: dict[str, Any] | None, n_candidates: int = 0, n_rejected: int = 0) -> None:
    """Markdown summary + a link to report.html (no-ops outside a Prefect run)."""
    try:
        from prefect.artifacts import create_link_artifact, create_markdown_artifact

        create_markdown_artifact(scene_summary_markdown(scene_id, manifest_path, html, timings, metrics, n_candidates, n_rejected),
                                 key=f"scene-{_key(scene_id)}", description=f"REACT3D summary of {scene_id}")
        if html:
            create_link_artifact(f"file://{Path(html).resolve()}", link_text="report.html",
                                 key=f"report-{_key(scene_id)}", description="self-contained viewer and report")
    except Exception:  # noqa: BLE001 - artifacts are for the UI; a conversion never fails over them
        pass


def publish_dataset_table(rows: list[dict[str, Any]], columns: Sequence[str]) -> None:
    """The ``dataset-summary`` table artifact: one row per scene, ``columns`` of each."""
    try:
        from prefect.artifacts import create_table_artifact

        create_table_artifact([{k: r[k] for k in columns} for r in rows], key="dataset-summary",
                              description=f"{sum(r['status'] == 'ok' for r in rows)}/{len(rows)} scenes converted")
    except Exception:  # noqa: BLE001 - the table is for the UI; the rows are returned either way
        pass
