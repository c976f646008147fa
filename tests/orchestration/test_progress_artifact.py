"""The flow's progress artifact is updated at stage ends and at most every few seconds in between (each
update is an API request; one per part and batch cost a cached conversion 1.3 s), while the CLI's hook
still sees every step."""

from __future__ import annotations

from prefect import flow

from flows.artifacts import Progress


def test_progress_artifact_updates_are_throttled_but_the_hook_sees_everything() -> None:
    seen: list[tuple[str, int, int]] = []
    now = [0.0]

    @flow(name="progress-throttle")
    def run() -> tuple[int, bool]:
        p = Progress(lambda *a: seen.append(a), min_interval_s=2.0, clock=lambda: now[0])
        for i in range(1, 31):  # 30 parts within one second: one update, then the stage's end
            now[0] += 1 / 30
            p("articulation", i, 30)
        now[0] += 5.0
        p("assembly", 1, 1)
        p("export", 0, 1)  # a stage start never updates
        return p.updates, p._artifact is not None

    updates, has_artifact = run()
    assert has_artifact
    assert updates == 3  # first step, end of articulation, end of assembly
    assert len(seen) == 32 and seen[-1] == ("export", 0, 1)
