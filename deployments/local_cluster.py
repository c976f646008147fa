"""A real multi-worker Prefect set-up on this machine: ``prefect server`` on 127.0.0.1, a process pool,
N ``prefect worker`` processes, the ``convert-scene`` deployment, and optionally an S3-compatible
object store (s3rver, a Node server that keeps objects on disk). Used by the distributed acceptance
test and benchmarks/bench_workers.py; every process it starts, it stops (``close``).

    with LocalCluster(home, n_workers=2) as c:
        c.convert_dataset(["ds", "--out", "out"])   # react3d convert-dataset --deployment ...
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DEPLOYMENT = "react3d-convert-scene/convert-scene"
S3RVER_BIN = ROOT / ".tools" / "s3rver" / "node_modules" / ".bin" / "s3rver"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_http(url: str, timeout: float, proc: subprocess.Popen[bytes] | None = None) -> None:
    """Wait until ``url`` answers 200 (raises TimeoutError; RuntimeError if ``proc`` died)."""
    t0 = time.time()
    while time.time() - t0 < timeout:
        if proc is not None and proc.poll() is not None:
            raise RuntimeError(f"{proc.args[:3]} exited with {proc.returncode} before {url} answered")
        try:
            with urllib.request.urlopen(url, timeout=2) as r:
                if r.status == 200:
                    return
        except OSError:
            time.sleep(0.5)
    raise TimeoutError(f"{url} did not answer within {timeout:.0f} s")


def kill_tree(pid: int, sig: int = signal.SIGKILL) -> list[int]:
    """Send ``sig`` to ``pid`` and all its descendants (a worker and the flow runs it started); their pids."""
    import psutil

    try:
        p = psutil.Process(pid)
        procs = [p, *p.children(recursive=True)]
    except psutil.NoSuchProcess:
        return []
    for q in procs:
        try:
            q.send_signal(sig)
        except psutil.NoSuchProcess:
            pass
    psutil.wait_procs(procs, timeout=10)
    return [q.pid for q in procs]


def s3rver_command() -> list[str] | None:
    """How to start s3rver here (``bash scripts/setup.sh test`` installs it), or None."""
    env = os.environ.get("REACT3D_S3RVER")
    for cand in (env, str(S3RVER_BIN), shutil.which("s3rver")):
        if cand and Path(cand).is_file():
            return [cand]
    return None


class S3Server:
    """s3rver on 127.0.0.1 with one bucket; objects are files under ``data``. ``env`` points clients at it.

    ``kill()`` and ``start()`` stop it the hard way and bring it back on the same port and folder (the
    store restarting under running workers)."""

    def __init__(self, data: Path, bucket: str = "react3d") -> None:
        cmd = s3rver_command()
        if cmd is None:
            raise FileNotFoundError("s3rver is not installed: run `bash scripts/setup.sh test` (needs npm)")
        self.cmd, self.data = cmd, data
        self.port = free_port()
        self.bucket = bucket
        data.mkdir(parents=True, exist_ok=True)
        self.log = open(data.parent / f"s3rver-{self.port}.log", "ab")  # noqa: SIM115 - closed in close()
        self.env = {"AWS_ENDPOINT_URL": f"http://127.0.0.1:{self.port}", "AWS_ACCESS_KEY_ID": "S3RVER",
                    "AWS_SECRET_ACCESS_KEY": "S3RVER", "AWS_DEFAULT_REGION": "us-east-1"}
        self.proc: subprocess.Popen[bytes] | None = None
        self.start()

    def start(self) -> None:
        """Start the server (again) on this port and folder; returns once it accepts connections."""
        self.proc = subprocess.Popen([*self.cmd, "--directory", str(self.data), "--address", "127.0.0.1", "--port",
                                      str(self.port), "--configure-bucket", self.bucket, "--silent"],
                                     stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True,
                                     # s3rver 3.7 encrypts listing continuation tokens (> 1000 keys) with a
                                     # cipher OpenSSL 3 (Node >= 17) keeps in its legacy provider
                                     env={**os.environ, "NODE_OPTIONS": "--openssl-legacy-provider"})
        t0 = time.time()
        while True:  # s3rver answers 403 to anonymous requests: wait for the port instead
            if self.proc.poll() is not None:
                raise RuntimeError(f"s3rver exited with {self.proc.returncode}")
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                break
            except OSError:
                if time.time() - t0 > 30:
                    raise TimeoutError("s3rver did not start within 30 s") from None
                time.sleep(0.2)

    def kill(self) -> None:
        """SIGKILL the server (a crash: requests in flight are cut, connections refused until ``start``)."""
        if self.proc is not None:
            kill_tree(self.proc.pid)
            self.proc = None

    def url(self, prefix: str) -> str:
        return f"s3://{self.bucket}/{prefix.strip('/')}"

    def object_file(self, key: str) -> Path:
        """The file s3rver keeps the bytes of ``key`` in (a test damages it there, behind the server's back)."""
        return self.data / self.bucket / f"{key.strip('/')}._S3rver_object"

    def close(self) -> None:
        if self.proc is not None:
            kill_tree(self.proc.pid, signal.SIGTERM)
            self.proc = None
        self.log.close()

    def __enter__(self) -> S3Server:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class LocalCluster:
    """Server + pool + ``n_workers`` process workers + the convert-scene deployment, all under ``home``.

    ``store`` is the ``REACT3D_STORE`` of every worker (None: one shared local folder ``home/store``);
    with a remote store each worker keeps its own mirror ``home/worker-<i>/cache``."""

    def __init__(self, home: Path, n_workers: int = 2, pool: str = "react3d-test", store: str | None = None,
                 extra_env: dict[str, str] | None = None, zombie_seconds: int = 45, worker_limit: int = 1) -> None:
        self.home, self.pool, self.n_workers, self.worker_limit = Path(home), pool, n_workers, worker_limit
        self.home.mkdir(parents=True, exist_ok=True)
        self.port = free_port()
        self.api = f"http://127.0.0.1:{self.port}/api"
        self.store = store or str(self.home / "store")
        self.env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_", "PYTEST_"))}
        self.env.update({
            "PREFECT_HOME": str(self.home / "prefect"), "PREFECT_API_URL": self.api, "PYTHONPATH": str(ROOT),
            "PREFECT_SERVER_ANALYTICS_ENABLED": "false", "PREFECT_LOGGING_LEVEL": "WARNING",
            "PREFECT_SERVER_LOGGING_LEVEL": "WARNING", "PREFECT_WORKER_QUERY_SECONDS": "2",
            "PREFECT_FLOWS_HEARTBEAT_FREQUENCY": "30", "REACT3D_STORE": self.store,
            **(extra_env or {})})
        from tasks.storage import result_storage_env

        self.env.update(result_storage_env(self.store))  # records beside the store, on every worker
        self.zombie_seconds = zombie_seconds
        self.server: subprocess.Popen[bytes] | None = None
        self.workers: list[subprocess.Popen[bytes]] = []
        self._logs: list[Any] = []

    # --- processes --------------------------------------------------------------------------------
    def _popen(self, args: list[str], name: str, env: dict[str, str] | None = None) -> subprocess.Popen[bytes]:
        log = open(self.home / f"{name}.log", "wb")  # noqa: SIM115 - closed in close()
        self._logs.append(log)
        return subprocess.Popen(args, env=env or self.env, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT,
                                start_new_session=True)

    def start(self) -> LocalCluster:
        self.server = self._popen([sys.executable, "-m", "prefect", "server", "start", "--host", "127.0.0.1",
                                   "--port", str(self.port)], "server")
        wait_http(f"{self.api}/health", 240, self.server)
        subprocess.run([sys.executable, str(ROOT / "deployments" / "setup.py"), "--pools", self.pool,
                        "--zombie-seconds", str(self.zombie_seconds), "--deploy-scene-from", str(ROOT)],
                       env=self.env, cwd=ROOT, check=True, capture_output=True, timeout=300)
        for i in range(self.n_workers):
            self.start_worker(i)
        return self

    def worker_env(self, i: int) -> dict[str, str]:
        env = dict(self.env)
        if "://" in self.store and not self.store.startswith("file://"):
            env["REACT3D_CACHE"] = str(self.home / f"worker-{i}" / "cache")  # each worker its own mirror
        return env

    def start_worker(self, i: int) -> subprocess.Popen[bytes]:
        w = self._popen([sys.executable, "-m", "prefect", "worker", "start", "--pool", self.pool, "--type", "process",
                         "--name", f"worker-{i}", "--limit", str(self.worker_limit)], f"worker-{i}", self.worker_env(i))
        if i < len(self.workers):
            self.workers[i] = w
        else:
            self.workers.append(w)
        return w

    def kill_worker(self, i: int) -> list[int]:
        """SIGKILL worker ``i`` and the flow-run processes it started (a machine dying)."""
        return kill_tree(self.workers[i].pid)

    def close(self) -> None:
        for w in self.workers:
            kill_tree(w.pid, signal.SIGTERM)
        if self.server is not None:
            kill_tree(self.server.pid, signal.SIGTERM)
        for log in self._logs:
            log.close()

    def __enter__(self) -> LocalCluster:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the dataset command and the API -----------------------------------------------------------
    def convert_dataset(self, args: list[str], concurrency: int = 4, max_attempts: int = 3,
                        timeout: float = 1800, wait: bool = True) -> subprocess.Popen[bytes] | subprocess.CompletedProcess[str]:
        """``react3d convert-dataset ARGS --deployment convert-scene`` against this server."""
        cmd = [sys.executable, "-m", "flows.cli", "convert-dataset", *args, "--deployment", DEPLOYMENT,
               "--concurrency", str(concurrency), "--max-attempts", str(max_attempts)]
        env = {**self.env, "REACT3D_CACHE": str(self.home / "client-cache"), "COLUMNS": "200"}
        if not wait:
            return self._popen(cmd, "convert-dataset", env)
        return subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=timeout)

    def post(self, path: str, body: dict[str, Any]) -> Any:
        req = urllib.request.Request(f"{self.api}{path}", data=json.dumps(body).encode(), method="POST",
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=30) as r:
            return json.loads(r.read())

    def scene_runs(self) -> list[dict[str, Any]]:
        """Every flow run of the convert-scene deployment (name ``<scene>-attempt<n>``), oldest first."""
        runs = self.post("/flow_runs/filter", {"sort": "EXPECTED_START_TIME_ASC", "limit": 200})
        return [r for r in runs if "-attempt" in r["name"]]

    def task_runs(self, flow_run_id: str) -> list[dict[str, Any]]:
        return self.post("/task_runs/filter", {"flow_runs": {"id": {"any_": [flow_run_id]}}, "limit": 200})

    def artifact(self, key: str) -> Any:
        arts = self.post("/artifacts/filter", {"artifacts": {"key": {"any_": [key]}}, "sort": "CREATED_DESC", "limit": 1})
        return json.loads(arts[0]["data"]) if arts else None
