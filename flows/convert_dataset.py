"""Flow ``convert_dataset``: many scenes; one failed scene never fails the others.

Two modes. Embedded (default, ``deployment=None``): scenes are subflows in threads of this process,
``scene_concurrency`` at a time. Distributed (``deployment="react3d-convert-scene/convert-scene"``):
one flow run per scene through that deployment (``run_deployment``, non-blocking), at most
``scene_concurrency`` in flight, so every worker of the pool takes scenes; a run that *crashed* (its
worker or machine died, OOM kill; marked Crashed by the worker or by the zombie automation of
deployments/setup.py) is submitted again, up to ``max_attempts`` runs in all, and resumes from the cached
tasks in the shared store on whichever worker picks it up; so is a run that failed because its object
store did not answer within its retry budget; a run that *failed* otherwise (bad input, a bug) is
reported once with its reason; a run that no worker starts within ``start_timeout`` seconds, or that does
not finish within ``run_timeout``, is cancelled and submitted again like a crashed one. Both modes end with the same table artifact (ok / failed with reason /
retries) and return its rows (docs/orchestration.md).
"""

from __future__ import annotations

import fnmatch
import json
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from tasks import prefect_env

prefect_env.configure()

from prefect import flow  # noqa: E402

from react3d_core.atomic import check_output_dir  # noqa: E402
from react3d_core.errors import InputError  # noqa: E402
from tasks import storage  # noqa: E402
from tasks.assembly import OUTPUT_KIND  # noqa: E402

from .artifacts import create_progress, publish_dataset_table, set_progress  # noqa: E402
from .convert_scene import convert_scene  # noqa: E402


SCAN_MARKERS = ("scans", "iphone", "dslr", "mesh_aligned_0.05.ply", "transforms.json")
"""Names whose presence makes a sub-folder of a dataset a scan (without ``--scenes`` / ``--glob``)."""


class RemoteScan:
    """A scan under a remote dataset root (``s3://bucket/scans/<name>``); workers read it through their
    scan cache (tasks/scan_cache.py). Quacks like the ``Path`` of a local scan where the dataset code needs it."""

    def __init__(self, url: str) -> None:
        self.url = url.rstrip("/")
        self.name = self.url.rsplit("/", 1)[-1]

    def resolve(self) -> RemoteScan:
        return self

    def __str__(self) -> str:
        return self.url

    def __repr__(self) -> str:
        return f"RemoteScan({self.url!r})"


def find_scenes(root: str | Path, scene_ids: list[str] | None = None, glob: str | None = None) -> list[Any]:
    """Scene folders under ``root``: the named ids, or those matching ``glob`` (default: every folder
    that looks like a scan: has scans/, iphone/, a mesh or a transforms.json). Under a remote ``root``
    (``s3://...``) the same, as :class:`RemoteScan` prefixes."""
    if storage.is_remote(root):
        return _find_remote_scenes(str(root).rstrip("/"), scene_ids, glob)
    root = Path(root)
    if scene_ids:
        return [root / s for s in scene_ids]
    found = []
    for d in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        if glob and not fnmatch.fnmatch(d.name, glob):
            continue
        if glob or any((d / n).exists() for n in SCAN_MARKERS):
            found.append(d)
    return found


def _find_remote_scenes(root: str, scene_ids: list[str] | None, glob: str | None) -> list[RemoteScan]:
    if scene_ids:
        return [RemoteScan(f"{root}/{s}") for s in scene_ids]
    # one flat listing of every key, not a listing per "folder": S3 servers differ in which common
    # prefixes they report for a delimiter (s3rver omits those whose keys are two levels deeper)
    children: dict[str, set[str]] = {}
    for rel in _remote_keys(root):
        parts = rel.split("/")
        if len(parts) >= 2:
            children.setdefault(parts[0], set()).add(parts[1])
    return [RemoteScan(f"{root}/{name}") for name, inner in sorted(children.items())
            if not name.startswith(".") and (fnmatch.fnmatch(name, glob) if glob else bool(inner & set(SCAN_MARKERS)))]


def _remote_keys(root: str) -> list[str]:
    """Every object under the prefix ``root``, relative to it."""
    fs, path = storage.filesystem(root)
    path = path.rstrip("/")
    try:
        return [f[len(path):].lstrip("/") for f in fs.find(path)]
    except FileNotFoundError:
        return []


def check_dataset_outputs(root: str | Path, scene_ids: list[str] | None, glob: str | None,
                          out_root: str | Path) -> list[Any]:
    """Refuse the whole run before any scene starts when one scene's output folder is unsafe to replace
    (see :func:`react3d_core.atomic.check_output_dir`) or a scene id is not a plain folder name
    (``..`` would put a scene's output at the parent of ``out_root``). Returns the scenes."""
    root_p = Path(root)
    remote_root = storage.is_remote(root)
    if remote_root and not _remote_keys(str(root).rstrip("/")):
        raise InputError(root, "dataset prefix not found (or holds nothing)")
    if not remote_root and not root_p.is_dir():
        raise InputError(root_p, "dataset folder not found")
    for s in scene_ids or []:
        if s in ("", ".", "..") or "/" in s or "\\" in s:
            raise InputError(root_p / s, "a scene id must be the name of a sub-folder of the dataset folder")
    scenes = find_scenes(root if remote_root else root_p, scene_ids, glob)
    if storage.is_remote(out_root):  # s3://...: each scene's prefix holds nothing react3d did not write
        for scene in scenes:
            storage.check_remote_output(f"{str(out_root).rstrip('/')}/{scene.name}")
        return scenes
    out = Path(out_root)
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise InputError(out, "exists and is not a folder; choose a new --out folder")
    for scene in scenes:
        check_output_dir(out / scene.name, () if remote_root else (scene, root_p), kind=OUTPUT_KIND)
    return scenes


def scene_out(out_root: str | Path, scene: str) -> str:
    """Output location of one scene: a folder under a local ``out_root``, a key prefix under a URL."""
    return f"{str(out_root).rstrip('/')}/{scene}" if storage.is_remote(out_root) else str(Path(out_root) / scene)


def count_parts(manifest: str) -> int:
    """Articulated objects in a published manifest (a local path or a URL)."""
    return len(json.loads(storage.read_text(manifest)).get("objects", []))


def _reason(exc_or_msg: Exception | str) -> str:
    if isinstance(exc_or_msg, Exception):
        msg = str(exc_or_msg).strip().splitlines()[0] if str(exc_or_msg).strip() else ""
        return f"{type(exc_or_msg).__name__}: {msg}"[:300] if msg else type(exc_or_msg).__name__
    return (exc_or_msg.strip().splitlines() or [""])[0][:300]


TABLE_COLUMNS = ("scene", "status", "parts", "seconds", "retries", "worker", "error")
"""Columns of the ``dataset-summary`` table artifact (and of the CLI's table)."""


def _row(scene: str, status: str, t0: float, *, parts: int = 0, manifest: str = "", error: str = "",
         retries: int = 0, worker: str = "", flow_run: str = "") -> dict[str, Any]:
    return {"scene": scene, "status": status, "parts": parts, "seconds": round(time.perf_counter() - t0, 1),
            "retries": retries, "worker": worker, "error": error, "manifest": manifest, "flow_run": flow_run}


def _one(scene: Any, out_root: str, config: dict[str, Any] | None) -> dict[str, Any]:
    t0 = time.perf_counter()
    try:
        manifest = convert_scene.with_options(name=f"convert-{scene.name}")(str(scene), scene_out(out_root, scene.name), config)
        return _row(scene.name, "ok", t0, parts=count_parts(manifest), manifest=manifest, worker="in-process")
    except Exception as exc:  # noqa: BLE001 - a failed scene is reported, the others go on
        return _row(scene.name, "failed", t0, error=_reason(exc), worker="in-process")


def fan_out(scenes: list[Any], out_root: str, config: dict[str, Any] | None, deployment: str,
            max_in_flight: int, max_attempts: int, poll_seconds: float = 2.0,
            start_timeout: float | None = None, run_timeout: float | None = None) -> list[dict[str, Any]]:
    """One flow run of ``deployment`` per scene, at most ``max_in_flight`` unfinished at a time; crashed
    runs are submitted again (up to ``max_attempts`` runs per scene). Rows in the order of ``scenes``.

    ``start_timeout``: seconds from submission within which a worker must start the run (state Running);
    ``run_timeout``: seconds from its start within which it must finish. A run past either is cancelled
    through the API (a worker that holds it stops its process) and, like a crashed one, submitted again
    while attempts remain; the reason of every earlier attempt goes to the row's ``error``.

    Paths sent to workers are absolute (a worker's working directory is not ours); outputs go to
    ``out_root/<scene>``, a folder every worker reaches or an fsspec URL."""
    from prefect.client.orchestration import get_client
    from prefect.deployments import run_deployment

    root_of = {s.name: str(s.resolve()) for s in scenes}
    out_abs = out_root if storage.is_remote(out_root) else str(Path(out_root).resolve())
    queue: deque[tuple[str, int]] = deque((s.name, 1) for s in scenes)
    started = {s.name: time.perf_counter() for s in scenes}
    running: dict[Any, _InFlight] = {}
    history: dict[str, list[str]] = {s.name: [] for s in scenes}
    rows: dict[str, dict[str, Any]] = {}
    with get_client(sync_client=True) as client:
        from prefect.exceptions import ObjectNotFound

        try:
            client.read_deployment_by_name(deployment)
        except ObjectNotFound:
            raise InputError(deployment, "no such deployment on this Prefect server (PREFECT_API_URL); run "
                                         "deployments/setup.py and `prefect deploy` first (docs/orchestration.md)") from None
        while queue or running:
            while queue and len(running) < max(1, max_in_flight):
                name, attempt = queue.popleft()
                fr = run_deployment(deployment, timeout=0, flow_run_name=f"{name}-attempt{attempt}",
                                    parameters={"scene_path": root_of[name], "out_dir": scene_out(out_abs, name),
                                                "config": config or {}},
                                    tags=["react3d", f"scene:{name}", f"attempt:{attempt}"])
                running[fr.id] = _InFlight(name, attempt, time.perf_counter())
            time.sleep(poll_seconds)
            for fid, run in list(running.items()):
                name, attempt = run.scene, run.attempt
                fr = client.read_flow_run(fid)
                state = fr.state
                worker = str((fr.labels or {}).get("prefect.worker.name", ""))
                common = {"retries": attempt - 1, "worker": worker, "flow_run": str(fid)}
                if state is None or not state.is_final():
                    why = run.overdue(state, start_timeout, run_timeout)
                    if why is None:
                        continue
                    del running[fid]
                    cancel_flow_run(client, fid, state, why)
                    if attempt < max_attempts:
                        history[name].append(f"attempt {attempt} cancelled: {why}")
                        queue.append((name, attempt + 1))  # like a crash: the next run resumes from the cache
                    else:
                        rows[name] = _row(name, "failed", started[name], error=_with_history(history[name], f"cancelled: {why}"), **common)
                    continue
                del running[fid]
                if state.is_completed():
                    try:
                        manifest = storage.output_manifest(scene_out(out_abs, name))  # a remote one: by its pointer
                        rows[name] = _row(name, "ok", started[name], parts=count_parts(manifest), manifest=manifest,
                                          error=_with_history(history[name], ""), **common)
                    except (OSError, ValueError, InputError) as exc:
                        rows[name] = _row(name, "failed", started[name], error=f"completed but its manifest is unreadable: {_reason(exc)}", **common)
                elif state.is_crashed() and attempt < max_attempts:
                    history[name].append(f"attempt {attempt} crashed: {_reason(state.message or state.name or '')}")
                    queue.append((name, attempt + 1))  # its finished tasks are cached: the next run resumes
                elif state.is_failed() and attempt < max_attempts and store_was_down(state.message):
                    history[name].append(f"attempt {attempt} failed: {_reason(state.message or '')}")
                    queue.append((name, attempt + 1))  # the store may be back: resume from the cache
                else:
                    why = "crashed" if state.is_crashed() else state.type.value.lower()
                    rows[name] = _row(name, "failed", started[name],
                                      error=_with_history(history[name], f"{why}: {_reason(state.message or state.name or '')}"), **common)
    return [rows[s.name] for s in scenes]


def store_was_down(message: str | None) -> bool:
    """Whether a failed run failed because its store did not answer within the retry budget
    (tasks/remote_fs.py): the one failure that submitting the scene again can fix. Prefect keeps only the
    message of a failed run (``Flow run encountered an exception: StoreUnavailableError: ...``)."""
    from tasks.remote_fs import StoreUnavailableError

    return f"{StoreUnavailableError.__name__}:" in (message or "")


class _InFlight:
    """One submitted flow run of a scene: when it was submitted and when this loop first saw it Running."""

    __slots__ = ("scene", "attempt", "submitted", "running_since")

    def __init__(self, scene: str, attempt: int, submitted: float) -> None:
        self.scene, self.attempt, self.submitted = scene, attempt, submitted
        self.running_since: float | None = None

    def overdue(self, state: Any, start_timeout: float | None, run_timeout: float | None) -> str | None:
        """Why this unfinished run must be cancelled now, or None.

        "Started" means Running: a run still Scheduled (no worker took it) or Pending (its worker never got
        its process going) counts against ``start_timeout``; the run time counts from the first poll that saw
        it Running (poll period granularity)."""
        now = time.perf_counter()
        if state is not None and state.is_running() and self.running_since is None:
            self.running_since = now
        if self.running_since is None:
            if start_timeout is not None and now - self.submitted > start_timeout:
                where = "no worker picked it up" if state is None or state.is_scheduled() else "its worker did not start it"
                return f"not started within {start_timeout:g} s ({where})"
            return None
        if run_timeout is not None and now - self.running_since > run_timeout:
            return f"not finished within {run_timeout:g} s of its start"
        return None


def cancel_flow_run(client: Any, flow_run_id: Any, state: Any, why: str) -> None:
    """Cancel a flow run through the API: a run no worker holds becomes Cancelled at once; one a worker
    holds (Pending, Running) becomes Cancelling, and that worker stops its process and marks it Cancelled."""
    from prefect.states import Cancelled, Cancelling

    held = state is not None and (state.is_pending() or state.is_running())
    new = (Cancelling if held else Cancelled)(message=f"react3d convert-dataset: {why}")
    client.set_flow_run_state(flow_run_id, new, force=True)


def _with_history(earlier: list[str], last: str) -> str:
    """The row's error: what ended each earlier attempt, then the last attempt's reason (if it failed)."""
    return "; ".join([*earlier, last] if last else earlier)


@flow(name="react3d-convert-dataset", persist_result=False)
def convert_dataset(root: str, scene_ids: list[str] | None = None, glob: str | None = None,
                    out_root: str = "react3d_out", config: dict[str, Any] | None = None,
                    scene_concurrency: int = 1, deployment: str | None = None,
                    max_attempts: int = 3, start_timeout: float | None = None,
                    run_timeout: float | None = None) -> list[dict[str, Any]]:
    """Convert every selected scene under ``root`` into ``out_root/<scene>``; returns one row per scene.

    ``deployment`` (e.g. ``react3d-convert-scene/convert-scene``) fans scenes out to the workers of its
    pool, with ``start_timeout`` / ``run_timeout`` seconds per run (see :func:`fan_out`); without it
    scenes run in this process."""
    scenes = check_dataset_outputs(root, scene_ids, glob, out_root)
    if deployment:
        rows = fan_out(scenes, out_root, config, deployment, scene_concurrency, max_attempts,
                       start_timeout=start_timeout, run_timeout=run_timeout)
        publish_dataset_table(rows, TABLE_COLUMNS)
        return rows
    rows: list[dict[str, Any]] = []
    progress = create_progress(f"{len(scenes)} scenes")
    with ThreadPoolExecutor(max_workers=max(1, scene_concurrency)) as pool:
        for row in pool.map(lambda s: _one(s, out_root, config), scenes):
            rows.append(row)
            set_progress(progress, 100.0 * len(rows) / max(len(scenes), 1))
    publish_dataset_table(rows, TABLE_COLUMNS)
    return rows
