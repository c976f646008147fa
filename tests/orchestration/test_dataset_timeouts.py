"""``convert-dataset --deployment``: a run that no worker starts, or that runs too long, is cancelled through
the API, reported with its reason and submitted again while attempts remain (the run's shared Prefect
server; a work pool with no worker)."""

from __future__ import annotations

import threading
import time
import uuid
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture()
def idle_deployment() -> str:
    """``convert-scene`` deployed to a fresh process pool that no worker serves; its full name."""
    from deployments.setup import ensure_pool
    from flows.convert_scene import convert_scene

    tag = uuid.uuid4().hex[:8]
    pool, name = f"react3d-idle-{tag}", f"idle-{tag}"
    ensure_pool(pool)
    convert_scene.from_source(source=str(ROOT), entrypoint="flows/convert_scene.py:convert_scene").deploy(
        name=name, work_pool_name=pool, print_next_steps=False)
    return f"react3d-convert-scene/{name}"


def _scenes(tmp_path: Path, n: int) -> Path:
    root = tmp_path / "data"
    for i in range(n):
        (root / f"s{i}" / "scans").mkdir(parents=True)  # never read: no worker runs them
    return root


def _runs_of(deployment: str) -> list[Any]:
    from prefect.client.orchestration import get_client
    from prefect.client.schemas.filters import DeploymentFilter, DeploymentFilterId

    with get_client(sync_client=True) as client:
        dep = client.read_deployment_by_name(deployment)
        return client.read_flow_runs(deployment_filter=DeploymentFilter(id=DeploymentFilterId(any_=[dep.id])))


def test_run_no_worker_starts_is_cancelled_reported_and_resubmitted(idle_deployment: str, tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    from flows.cli import main

    monkeypatch.setenv("COLUMNS", "250")
    root = _scenes(tmp_path, 2)
    t0 = time.perf_counter()
    rc = main(["convert-dataset", str(root), "--out", str(tmp_path / "out"), "--deployment", idle_deployment,
               "--concurrency", "2", "--max-attempts", "2", "--start-timeout", "3"])
    wall = time.perf_counter() - t0
    out = capsys.readouterr().out
    assert rc == 1
    assert "0/2 scenes converted" in out
    reason = "not started within 3 s (no worker picked it up)"
    assert out.count(f"attempt 1 cancelled: {reason}; cancelled: {reason}") == 2, out
    runs = _runs_of(idle_deployment)
    assert sorted(r.name for r in runs) == ["s0-attempt1", "s0-attempt2", "s1-attempt1", "s1-attempt2"]
    assert {r.state_type.value for r in runs} == {"CANCELLED"}
    assert all(reason in r.state.message for r in runs)
    late = [(r.state.timestamp - r.created).total_seconds() for r in runs]  # submission -> cancelled
    print(f"unstarted runs cancelled {min(late):.1f}-{max(late):.1f} s after submission (start timeout 3 s)")
    assert all(3 <= s < 3 + 2 + 5 for s in late), late  # the timeout plus one poll period (2 s) plus slack
    # two attempts of 3 s each, polled every 2 s: reported within ~2 x (3 + 2) s plus the flow's own start
    assert wall < 2 * (3 + 2) + 20, wall


def test_run_over_its_run_timeout_is_cancelled_through_its_worker(idle_deployment: str, tmp_path: Path) -> None:
    """A run that started but does not finish: the API's Cancelling state, which tells its worker to stop it.

    No worker process runs here: a thread proposes Running for each new run as a worker would."""
    from prefect.client.orchestration import get_client
    from prefect.states import Running

    from flows.convert_dataset import fan_out

    root = _scenes(tmp_path, 1)
    stop = threading.Event()

    def play_worker() -> None:
        with get_client(sync_client=True) as client:
            while not stop.is_set():
                for r in _runs_of(idle_deployment):
                    if r.state_type.value == "SCHEDULED":
                        client.set_flow_run_state(r.id, Running(), force=True)
                time.sleep(0.2)

    th = threading.Thread(target=play_worker, daemon=True)
    th.start()
    try:
        t0 = time.perf_counter()
        rows = fan_out([root / "s0"], str(tmp_path / "out"), None, idle_deployment, max_in_flight=1,
                       max_attempts=2, poll_seconds=0.5, start_timeout=30, run_timeout=2)
        wall = time.perf_counter() - t0
    finally:
        stop.set()
        th.join(timeout=10)
    (row,) = rows
    why = "not finished within 2 s of its start"
    assert row["status"] == "failed" and row["retries"] == 1
    assert row["error"] == f"attempt 1 cancelled: {why}; cancelled: {why}"
    runs = {r.name: r for r in _runs_of(idle_deployment)}
    assert sorted(runs) == ["s0-attempt1", "s0-attempt2"]
    assert {r.state_type.value for r in runs.values()} == {"CANCELLING"}  # a worker would now stop its process
    assert wall < 2 * (2 + 0.5 + 1) + 5, wall
