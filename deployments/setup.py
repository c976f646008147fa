"""One-time set-up of a Prefect server for dataset runs on many workers (docs/orchestration.md).

    python deployments/setup.py                      # pools, gpu limit, zombie automation, result block
    prefect --no-prompt deploy --all --prefect-file deployments/prefect.yaml

What it creates, each idempotently: the process pools ``react3d-cpu`` and ``react3d-gpu``, the global
concurrency limit ``gpu`` (1), the automation that marks a flow run Crashed when its heartbeats stop
(a worker or machine died: ``convert_dataset`` then submits the scene again), and, for
``REACT3D_STORE=s3://...``, the ``remote-file-system/react3d-results`` block for result records.
``--deploy-scene-from DIR`` also deploys ``convert-scene`` from a source folder (tests, quick starts).
"""

from __future__ import annotations

import argparse
import sys
from datetime import timedelta
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

ZOMBIE_AUTOMATION = "react3d: crash flow runs whose heartbeats stopped"
HEARTBEAT_SECONDS = 30
"""``PREFECT_FLOWS_HEARTBEAT_FREQUENCY`` the deployments set for their runs (Prefect's minimum)."""


def ensure_pool(name: str, concurrency: int | None = None) -> None:
    """A process work pool ``name`` (kept as it is when it exists)."""
    from prefect.client.orchestration import get_client
    from prefect.client.schemas.actions import WorkPoolCreate
    from prefect.exceptions import ObjectAlreadyExists

    with get_client(sync_client=True) as client:
        try:
            client.create_work_pool(WorkPoolCreate(name=name, type="process", concurrency_limit=concurrency))
        except ObjectAlreadyExists:
            pass


def ensure_gpu_limit(limit: int = 1) -> None:
    """Global concurrency limit ``gpu``: model tasks (tag/limit ``gpu``) one at a time per GPU."""
    from prefect.client.orchestration import get_client
    from prefect.client.schemas.actions import GlobalConcurrencyLimitCreate
    from prefect.exceptions import ObjectAlreadyExists

    with get_client(sync_client=True) as client:
        try:
            client.create_global_concurrency_limit(GlobalConcurrencyLimitCreate(name="gpu", limit=limit))
        except ObjectAlreadyExists:
            pass


def ensure_zombie_automation(within_seconds: int = 90) -> None:
    """Prefect's documented zombie detection: no heartbeat (nor final state) within ``within_seconds`` of
    the last one marks the run Crashed. Without it a run whose machine died stays Running forever."""
    from prefect.automations import Automation
    from prefect.client.schemas.objects import StateType
    from prefect.events.actions import ChangeFlowRunState
    from prefect.events.schemas.automations import EventTrigger, Posture
    from prefect.events.schemas.events import ResourceSpecification

    try:
        old = Automation.read(name=ZOMBIE_AUTOMATION)
    except ValueError:
        old = None
    if old is not None:
        old.delete()
    Automation(
        name=ZOMBIE_AUTOMATION,
        trigger=EventTrigger(
            after={"prefect.flow-run.heartbeat"},
            expect={"prefect.flow-run.heartbeat", "prefect.flow-run.Completed", "prefect.flow-run.Failed",
                    "prefect.flow-run.Cancelled", "prefect.flow-run.Crashed"},
            match=ResourceSpecification({"prefect.resource.id": ["prefect.flow-run.*"]}),
            for_each={"prefect.resource.id"},
            posture=Posture.Proactive,
            threshold=1,
            within=timedelta(seconds=within_seconds),
        ),
        actions=[ChangeFlowRunState(state=StateType.CRASHED,
                                    message="no heartbeat: its worker or machine stopped (react3d zombie automation)")],
    ).create()


def deploy_convert_scene(source: Path, pool: str, concurrency: int = 4, env: dict[str, str] | None = None) -> Any:
    """Deploy ``convert-scene`` from ``source`` (a folder every worker sees) to ``pool``."""
    from flows.convert_scene import convert_scene

    from tasks import storage

    job_env = {"PREFECT_FLOWS_HEARTBEAT_FREQUENCY": str(HEARTBEAT_SECONDS)}
    store = storage.settings().store
    if storage.is_remote(store):  # the same URL on every worker; credentials stay in the workers' env
        job_env.update({"REACT3D_STORE": str(store), **storage.result_storage_env(store)})
    job_env.update(env or {})
    return convert_scene.from_source(source=str(source), entrypoint="flows/convert_scene.py:convert_scene").deploy(
        name="convert-scene", work_pool_name=pool, concurrency_limit=concurrency,
        job_variables={"env": job_env}, tags=["react3d"], print_next_steps=False)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pools", nargs="*", default=["react3d-cpu", "react3d-gpu"])
    p.add_argument("--zombie-seconds", type=int, default=90,
                   help="Seconds without a heartbeat before a run counts as crashed (> 30, the heartbeat period).")
    p.add_argument("--deploy-scene-from", type=Path, default=None, help="Also deploy convert-scene from this folder.")
    p.add_argument("--scene-concurrency", type=int, default=4)
    a = p.parse_args(argv)
    from tasks import prefect_env, storage

    prefect_env.configure()
    for name in a.pools:
        ensure_pool(name)
    ensure_gpu_limit()
    ensure_zombie_automation(a.zombie_seconds)
    block = storage.ensure_result_block()
    if a.deploy_scene_from is not None:
        deploy_convert_scene(a.deploy_scene_from.resolve(), a.pools[0], a.scene_concurrency)
    print(f"pools {', '.join(a.pools)}; gcl gpu; zombie automation ({a.zombie_seconds} s)"
          + (f"; result storage {block}" if block else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
