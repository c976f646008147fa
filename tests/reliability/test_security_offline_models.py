"""``--perception models`` without weights fails in seconds with one line, instead of
minutes of hub retries. Nothing is downloaded: the hub endpoint is a loopback socket that never answers
(what a closed network looks like to an HTTP client), and the Hugging Face cache is an empty folder."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytestmark = pytest.mark.integration  # whole-process runs (CLI subprocesses, Prefect servers)

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("transformers")


@pytest.fixture()
def silent_hub() -> Iterator[tuple[str, list[socket.socket]]]:
    """An HTTP endpoint that accepts connections and never replies; yields (url, accepted connections)."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(16)
    conns: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                conns.append(srv.accept()[0])
            except OSError:
                continue

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    yield f"http://127.0.0.1:{srv.getsockname()[1]}", conns
    stop.set()
    t.join()
    for c in conns:
        c.close()
    srv.close()


def _env(tmp_path: Path, hub: str, offline: bool) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HF_", "TRANSFORMERS_", "PREFECT_", "REACT3D_"))}
    env.update(HF_HOME=str(tmp_path / "hf"), HF_ENDPOINT=hub, PYTHONPATH=str(ROOT),
               PREFECT_HOME=str(tmp_path / "prefect"), REACT3D_CACHE=str(tmp_path / "cache"),
               PREFECT_LOCAL_STORAGE_PATH=str(tmp_path / "prefect" / "storage"))
    if offline:
        env["HF_HUB_OFFLINE"] = "1"
    return env


BUILD = ("from react3d_core.config import PerceptionConfig\n"
         "from react3d_models import make_model_perception\n"
         "make_model_perception(PerceptionConfig(backend='models', models={'device': 'cpu'}))\n")


@pytest.mark.parametrize("offline", [False, True], ids=["hub-silent", "HF_HUB_OFFLINE"])
def test_missing_weights_fail_in_seconds_with_one_line(tmp_path: Path, silent_hub, offline: bool) -> None:  # noqa: ANN001
    hub, connections = silent_hub
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", BUILD], env=_env(tmp_path, hub, offline), cwd=ROOT,
                       capture_output=True, text=True, timeout=300)
    seconds = time.perf_counter() - t0
    assert p.returncode != 0
    last = p.stderr.strip().splitlines()[-1]
    assert last.startswith("react3d_models.runtime.ModelUnavailableError: model weights not available on this machine")
    for model in ("IDEA-Research/grounding-dino-tiny", "facebook/sam-vit-huge", "llava-hf/llava-1.5-7b-hf"):
        assert model in last  # every missing model named at once, not one per attempt
    assert ("HF_HUB_OFFLINE=1" if offline else "did not answer within 3 s") in last
    # python + torch + transformers import ~5-10 s on a busy 2-core box; the check itself is <= 4 s
    assert seconds < 60, seconds
    assert not any((tmp_path / "hf").rglob("*.safetensors"))
    assert "huggingface-cli download" in last
    time.sleep(0.3)
    assert len(connections) == (0 if offline else 1)  # one probe, no download attempts, no retries


def test_probe_asks_the_hub_once(silent_hub) -> None:  # noqa: ANN001
    from react3d_models.runtime import HUB_PROBE_TIMEOUT_S, hub_reachable

    hub, connections = silent_hub
    os.environ["HF_ENDPOINT"] = hub
    try:
        t0 = time.perf_counter()
        assert hub_reachable() is False
        assert time.perf_counter() - t0 < HUB_PROBE_TIMEOUT_S + 1.5
    finally:
        del os.environ["HF_ENDPOINT"]
    time.sleep(0.3)
    assert len(connections) == 1


def test_local_folder_is_found_without_the_hub(tmp_path: Path) -> None:
    from react3d_models.runtime import ModelNeed, ModelUnavailableError, check_models_available, hub_kwargs, locally_available

    local = tmp_path / "my-sam"
    local.mkdir()
    (local / "config.json").write_text("{}")
    assert locally_available(str(local)) and hub_kwargs(str(local)) == {"local_files_only": True}
    check_models_available([ModelNeed("SAM", str(local), "sam_model")])  # no probe, no error
    with pytest.raises(ModelUnavailableError, match="local folder does not exist.*perception.models.sam_model"):
        check_models_available([ModelNeed("SAM", str(tmp_path / "typo"), "sam_model")])
