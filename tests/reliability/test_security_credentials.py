"""An API key never travels in an endpoint URL (it would be stored in scene.json and in
Prefect's flow-run parameters); keys come from the environment or a Prefect Secret block."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

ROOT = Path(__file__).resolve().parents[2]
SECRET = "sk-test-7f3a9c1e"


@pytest.mark.parametrize("field", ["tag_filter_endpoint", "articulation_endpoint"])
@pytest.mark.parametrize("value", [
    f"https://api.example.com/v1?api_key={SECRET}",
    f"https://api.example.com/v1?model=x&key={SECRET}",
    f"https://api.example.com/v1?access_token={SECRET}",
    f"https://user:{SECRET}@api.example.com/v1",
    f"https://{SECRET}@api.example.com/v1",
    f"python opd_server.py --api-key {SECRET}",
    f"python opd_client.py --url 'https://h/predict?token={SECRET}'",
])
def test_endpoint_with_credentials_is_a_config_error_that_does_not_echo_it(field: str, value: str) -> None:
    from react3d_core.config import PipelineConfig
    from react3d_core.errors import ConfigError

    with pytest.raises(ConfigError) as e:
        PipelineConfig().with_overrides({"perception": {"models": {field: value}}})
    msg = str(e.value)
    assert SECRET not in msg and f"perception.models.{field}" in msg and "environment" in msg and "\n" not in msg
    with pytest.raises(ConfigError):
        PipelineConfig.model_validate({"perception": {"models": {field: value}}})


@pytest.mark.parametrize("value", ["http://127.0.0.1:8000/v1", "https://api.example.com/v1?model=llava&monkey=1",
                                   "python opd_server.py --port 9000 --keyframes 5", "/opt/opdmulti/run.sh"])
def test_plain_endpoints_are_accepted(value: str) -> None:
    from react3d_core.config import ModelsConfig

    assert ModelsConfig(tag_filter_endpoint=value, articulation_endpoint=value).articulation_endpoint == value


def test_convert_refuses_a_key_in_the_config_and_stores_it_nowhere(synthetic_scene, tmp_path: Path) -> None:  # noqa: ANN001
    scene = synthetic_scene(seed=5, n_frames=12, kind="dresser")
    home = tmp_path / "home"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    env.update(PREFECT_HOME=str(home), PREFECT_LOCAL_STORAGE_PATH=str(home / "storage"),
               REACT3D_CACHE=str(home / "cache"), PYTHONPATH=str(ROOT))
    cfg = {"perception": {"backend": "oracle", "models": {"tag_filter_endpoint": f"https://api.example.com/v1?api_key={SECRET}"}}}
    p = subprocess.run([sys.executable, "-m", "flows.cli", "convert", str(scene), "--out", str(tmp_path / "out"),
                        "--config", json.dumps(cfg)], env=env, cwd=ROOT, capture_output=True, text=True, timeout=600,
                       start_new_session=True)
    assert p.returncode != 0
    assert "tag_filter_endpoint carries a credential" in p.stderr + p.stdout
    assert SECRET not in p.stderr + p.stdout
    assert not (tmp_path / "out").exists()
    leaks = [f for d in (home, tmp_path) for f in d.rglob("*") if f.is_file() and SECRET.encode() in f.read_bytes()]
    assert leaks == []


class _Recorder(BaseHTTPRequestHandler):
    seen: list[str | None] = []

    def do_POST(self) -> None:  # noqa: N802 - http.server API
        self.rfile.read(int(self.headers.get("Content-Length", 0)))
        type(self).seen.append(self.headers.get("Authorization"))
        body = json.dumps({"predictions": []}).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: object) -> None:
        return


def test_keys_come_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("torch")
    from react3d_models.opdmulti import OPDMultiClient
    from react3d_models.runtime import api_key

    monkeypatch.delenv("REACT3D_OPDMULTI_API_KEY_BLOCK", raising=False)
    monkeypatch.setenv("REACT3D_OPDMULTI_API_KEY", SECRET)
    key = api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK")
    assert key == SECRET
    monkeypatch.delenv("REACT3D_OPDMULTI_API_KEY")
    assert api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK") is None
    server = ThreadingHTTPServer(("127.0.0.1", 0), _Recorder)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        client = OPDMultiClient(f"http://127.0.0.1:{server.server_address[1]}/predict", 10, 0.5, api_key=key)
        client._call(b"{}")
    finally:
        server.shutdown()
    assert _Recorder.seen == [f"Bearer {SECRET}"]


SECRET_BLOCK = """
import os, sys
from prefect.blocks.system import Secret
from react3d_models.runtime import api_key
Secret(value=sys.argv[1]).save("react3d-opdmulti-key")
os.environ["REACT3D_OPDMULTI_API_KEY_BLOCK"] = "react3d-opdmulti-key"
print("KEY", api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK") == sys.argv[1])
os.environ["REACT3D_OPDMULTI_API_KEY_BLOCK"] = "no-such-block"
try:
    api_key(("REACT3D_OPDMULTI_API_KEY",), "REACT3D_OPDMULTI_API_KEY_BLOCK")
except Exception as exc:
    print("MISSING", type(exc).__name__, str(exc))
"""


def test_keys_come_from_a_prefect_secret_block(tmp_path: Path, prefect_server) -> None:  # noqa: ANN001
    """A real Prefect server (the run's, used from another process): the key is read from a Secret block."""
    pytest.importorskip("torch")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PREFECT_", "REACT3D_"))}
    env.update(PREFECT_HOME=str(tmp_path / "prefect"), PREFECT_API_URL=prefect_server.url, PYTHONPATH=str(ROOT),
               PREFECT_LOGGING_LEVEL="ERROR")
    p = subprocess.Popen([sys.executable, "-c", SECRET_BLOCK, SECRET], env=env, cwd=ROOT, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = p.communicate(timeout=600)
    finally:  # nothing it started outlives the test
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(p.pid, signal.SIGKILL)
    assert "KEY True" in out, err[-2000:]
    missing = next(ln for ln in out.splitlines() if ln.startswith("MISSING"))
    assert missing.startswith("MISSING ConfigError REACT3D_OPDMULTI_API_KEY_BLOCK='no-such-block'") and SECRET not in missing
