"""A real `prefect server` on 127.0.0.1, a process work pool, the convert-dataset deployment, a run
triggered through the API and completed by a worker (slow: a minute or two on 2 cores)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from deployments.local_cluster import wait_http

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_deploy_and_run_convert_dataset(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    import shutil

    data = tmp_path / "data"
    shutil.copytree(synthetic_scene(seed=3, n_frames=12, kind="dresser"), data / "dresser")
    port = _free_port()
    api = f"http://127.0.0.1:{port}/api"
    env = {**os.environ, "PREFECT_HOME": str(tmp_path / "home"), "PREFECT_API_URL": api,
           "REACT3D_CACHE": str(tmp_path / "cache"), "PREFECT_SERVER_ANALYTICS_ENABLED": "false",
           "PREFECT_LOGGING_LEVEL": "WARNING", "PYTHONPATH": str(ROOT)}
    env.pop("PREFECT_API_KEY", None)
    server = subprocess.Popen([sys.executable, "-m", "prefect", "server", "start", "--host", "127.0.0.1", "--port", str(port)],
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        wait_http(f"{api}/health", 180)
        subprocess.run([sys.executable, "-m", "prefect", "work-pool", "create", "react3d-test", "--type", "process"],
                       env=env, check=True, capture_output=True, cwd=ROOT)
        deploy = (
            "from flows.convert_dataset import convert_dataset\n"
            f"convert_dataset.from_source(source={str(ROOT)!r}, entrypoint='flows/convert_dataset.py:convert_dataset').deploy("
            "name='convert-dataset', work_pool_name='react3d-test', "
            f"parameters={{'root': {str(data)!r}, 'out_root': {str(tmp_path / 'out')!r}, "
            "'config': {'perception': {'backend': 'oracle'}, 'frames': {'stride': 1}, 'export': {'formats': []}}})\n"
        )
        subprocess.run([sys.executable, "-c", deploy], env=env, check=True, capture_output=True, cwd=ROOT)
        worker = subprocess.Popen([sys.executable, "-m", "prefect", "worker", "start", "--pool", "react3d-test"],
                                  env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
        trigger = (
            "from prefect.deployments import run_deployment\n"
            "r = run_deployment('react3d-convert-dataset/convert-dataset', timeout=600)\n"
            "print(r.state.type.value)\n"
        )
        out = subprocess.run([sys.executable, "-c", trigger], env=env, check=True, capture_output=True, text=True,
                             cwd=ROOT, timeout=900)
        assert out.stdout.strip().splitlines()[-1] == "COMPLETED", out.stdout + out.stderr
        assert (tmp_path / "out" / "dresser" / "scene.json").exists()
    finally:
        for p in (worker, server):
            if p is not None:
                p.terminate()
                try:
                    p.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    p.kill()
