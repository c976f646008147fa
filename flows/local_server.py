"""The local Prefect server that react3d commands share when no ``PREFECT_API_URL`` is set.

The first command that runs flows starts it (``python -m flows.local_server``) in a session of its
own, so that killing the command (even with ``kill -9``) does not take it down while another command
uses it. It serves Prefect's API and UI on 127.0.0.1 at a free port, with its SQLite database in
``PREFECT_HOME`` like ``prefect server start`` (so ``react3d server`` shows the same history). Later
commands find it through a state file and reuse it: no start-up, no migrations, no imports of the
server modules.

Each command holds a *lease* while it runs: a shared ``flock`` on the server's lease file, which the
kernel drops when the command exits or is killed. Once no command has held a lease for
``REACT3D_SERVER_IDLE_S`` seconds (default 600) the server stops itself: nothing is left running.

Files in ``$PREFECT_HOME/react3d-server/``: ``state.json`` (pid, url, start time), ``lock`` (an
exclusive ``flock`` around reading, starting, replacing and retiring a server: two commands starting
at once end up with one server), ``lease-<port>`` (one per server), ``server.log`` (its output).
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from react3d_core.errors import React3DError

IDLE_ENV = "REACT3D_SERVER_IDLE_S"
IDLE_S = 600.0
"""Seconds without any command's lease after which the server stops itself."""
START_TIMEOUT_ENV = "PREFECT_SERVER_EPHEMERAL_STARTUP_TIMEOUT_SECONDS"
START_TIMEOUT_S = 120.0
"""How long a command waits for a server it starts (a fresh database is migrated first: ~15 s)."""
POLL_S = 0.5
ORPHAN_GRACE_S = 30.0
"""A server that never appears in the state file (its starter was killed before writing it) leaves."""
SUBDIR = "react3d-server"
MODULE = "flows.local_server"
NOTE = "react3d: started a local Prefect server, UI at {ui} (later commands reuse it; it stops after {idle} unused)"


class ServerError(React3DError):
    """The local Prefect server could not be started or does not answer."""


@dataclass
class LocalServer:
    """A running (or starting) local server, as one command sees it."""

    url: str
    pid: int
    started: bool
    """True when this process started it."""
    folder: Path
    lease_fd: int | None = None

    @property
    def ui(self) -> str:
        return self.url.removesuffix("/api")

    def wait_ready(self, timeout: float | None = None) -> None:
        """Block until the API answers; a server that died or never answers is a one-line error."""
        timeout = start_timeout() if timeout is None else timeout
        t0 = time.monotonic()
        while not healthy(self.url, timeout=2.0):
            if not alive(self.pid):
                raise ServerError(f"the local Prefect server exited while starting: {log_tail(self.folder)} "
                                  f"(log: {self.folder / 'server.log'})")
            if time.monotonic() - t0 > timeout:
                raise ServerError(f"the local Prefect server (pid {self.pid}) did not answer at {self.url} within "
                                  f"{timeout:.0f} s (log: {self.folder / 'server.log'}); raise {START_TIMEOUT_ENV} "
                                  "or start one yourself (`react3d server`) and set PREFECT_API_URL")
            time.sleep(0.1)

    def release(self) -> None:
        """Drop this process's lease (the kernel does it at exit; in-process users may do it earlier)."""
        if self.lease_fd is not None:
            os.close(self.lease_fd)
            self.lease_fd = None


# --- small helpers --------------------------------------------------------------------------------------

def _seconds(name: str, default: float) -> float:
    text = os.environ.get(name) or ""
    try:
        return float(text) if text else default
    except ValueError:
        raise ServerError(f"{name}={text!r} is not a number of seconds") from None


def idle_seconds() -> float:
    return _seconds(IDLE_ENV, IDLE_S)


def start_timeout() -> float:
    return _seconds(START_TIMEOUT_ENV, START_TIMEOUT_S)


def folder(home: str | Path) -> Path:
    d = Path(home).expanduser() / SUBDIR
    d.mkdir(parents=True, exist_ok=True)
    return d


def healthy(url: str, timeout: float = 3.0) -> bool:
    """Whether a Prefect API answers ``GET <url>/health`` (plain urllib: no client set-up cost)."""
    try:
        with urllib.request.urlopen(url.rstrip("/") + "/health", timeout=timeout) as resp:  # noqa: S310 (loopback)
            return resp.status == 200
    except (urllib.error.URLError, OSError, ValueError):
        return False


def alive(pid: int) -> bool:
    """Running and not a zombie (an exited child not yet reaped holds nothing)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def is_server(pid: int) -> bool:
    """``pid`` is a local server process (not another program that got the pid of a dead one)."""
    try:
        args = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return False
    return alive(pid) and MODULE.encode() in args


def log_tail(d: Path) -> str:
    try:
        lines = [ln.strip() for ln in (d / "server.log").read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return "no log"
    return lines[-1][:300] if lines else "no output"


@contextlib.contextmanager
def _locked(path: Path, blocking: bool = True) -> Iterator[bool]:
    """An exclusive ``flock`` on ``path`` (yields False when ``blocking`` is off and it is taken)."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
        except BlockingIOError:
            yield False
            return
        yield True
    finally:
        os.close(fd)  # closing the descriptor releases the lock


def read_state(d: Path) -> dict | None:
    try:
        st = json.loads((d / "state.json").read_text())
    except (OSError, ValueError):
        return None
    return st if isinstance(st, dict) and isinstance(st.get("pid"), int) and isinstance(st.get("url"), str) else None


def _write_state(d: Path, st: dict) -> None:
    tmp = d / f".state.{os.getpid()}.tmp"
    tmp.write_text(json.dumps(st))
    os.replace(tmp, d / "state.json")


def lease_path(d: Path, url: str) -> Path:
    return d / f"lease-{url.rsplit(':', 1)[1].split('/')[0]}"


def _take_lease(path: Path) -> int:
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    fcntl.flock(fd, fcntl.LOCK_SH)
    return fd


def lease_free(path: Path) -> bool:
    """No process holds a lease on ``path`` (an exclusive try-lock succeeds; released at once)."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    except OSError:
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    finally:
        os.close(fd)
    return True


# --- what a command does --------------------------------------------------------------------------------

def connect(home: str | Path, idle_s: float | None = None) -> LocalServer:
    """Reuse the local server of ``home`` (``PREFECT_HOME``) or start one that stops after ``idle_s``
    unused seconds (default: ``REACT3D_SERVER_IDLE_S`` or 600), and hold a lease on it for the life of
    this process. Does not wait for a starting server: see :meth:`LocalServer.wait_ready`.

    A state file naming a dead process, another program, a server of another interpreter or Prefect
    version, or one that has been up long enough to answer but does not, is replaced by a new server
    (the old one leaves once its own commands end)."""
    d = folder(home)
    with _locked(d / "lock"):
        st = read_state(d)
        if st is not None and _usable(st):
            return LocalServer(st["url"], st["pid"], False, d, _take_lease(lease_path(d, st["url"])))
        return _start(Path(home).expanduser(), d, idle_seconds() if idle_s is None else idle_s)


def _runtime() -> dict[str, str]:
    """What a server must share with the command that reuses it: the interpreter and Prefect's version."""
    import importlib.metadata

    return {"python": sys.executable, "prefect": importlib.metadata.version("prefect")}


def _usable(st: dict) -> bool:
    if not is_server(st["pid"]) or st.get("runtime") != _runtime():
        return False
    starting = time.time() - float(st.get("started", 0)) < start_timeout()
    return starting or healthy(st["url"], timeout=5.0)


def _start(home: Path, d: Path, idle_s: float) -> LocalServer:
    """Bind the port here (so the URL is known at once and no other program can take it), hand the
    listening socket to a detached server process, record it."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("127.0.0.1", 0))
        sock.listen(128)
        url = f"http://127.0.0.1:{sock.getsockname()[1]}/api"
        lease = lease_path(d, url)
        for old in d.glob("lease-*"):  # of servers gone (a running one recreates its file when it checks)
            if old != lease and lease_free(old):
                old.unlink(missing_ok=True)
        lease_fd = _take_lease(lease)  # before the server exists: it never sees itself unused
        env = {**os.environ, "PREFECT_HOME": str(home)}  # its database lives there
        root = str(Path(__file__).resolve().parents[1])
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
        with open(d / "server.log", "wb") as log:
            proc = subprocess.Popen(
                [sys.executable, "-m", MODULE, "--folder", str(d), "--fd", str(sock.fileno()),
                 "--lease", str(lease), "--idle", str(idle_s)],
                stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, pass_fds=(sock.fileno(),),
                start_new_session=True, cwd=root, env=env)
    finally:
        sock.close()  # the server has its own copy
    _write_state(d, {"pid": proc.pid, "url": url, "started": time.time(), "idle_s": idle_s, "runtime": _runtime()})
    _children.append(proc)  # reaped when this process checks on it or exits (init adopts it then)
    return LocalServer(url, proc.pid, True, d, lease_fd)


_children: list[subprocess.Popen[bytes]] = []


def stop_if_unused(home: str | Path, timeout: float = 30.0) -> bool:
    """Stop the local server of ``home`` now if no process holds a lease on it (the end of a test
    session, a user who wants the memory back); True when none is left running."""
    d = folder(home)
    with _locked(d / "lock"):
        st = read_state(d)
        if st is None or not is_server(st["pid"]):
            (d / "state.json").unlink(missing_ok=True)
            return True
        if not lease_free(lease_path(d, st["url"])):
            return False
        (d / "state.json").unlink(missing_ok=True)
        with contextlib.suppress(ProcessLookupError):
            os.kill(st["pid"], signal.SIGTERM)
    t0 = time.monotonic()
    while alive(st["pid"]) and time.monotonic() - t0 < timeout:
        _reap()
        time.sleep(0.1)
    if alive(st["pid"]):
        with contextlib.suppress(ProcessLookupError):
            os.kill(st["pid"], signal.SIGKILL)
    _reap()
    return True


def _reap() -> None:
    for p in list(_children):
        if p.poll() is not None:
            _children.remove(p)


# --- the command's side, once per process ----------------------------------------------------------------

_attached: LocalServer | None = None
_planned = False


def plan() -> None:
    """Say that this process will :func:`attach` (the CLI, before its checks): Prefect's temporary
    server, and the watchdog that would start it, are not needed."""
    global _planned
    _planned = True


def planned() -> bool:
    return _planned


def attach() -> LocalServer | None:
    """Point this process's Prefect at the local server of its ``PREFECT_HOME``, starting it if none
    runs, unless a server is named by ``PREFECT_API_URL`` (environment or profile: the user's wins).
    Returns at once; :func:`ready` waits for a starting server. Prints one line when it starts one."""
    global _attached
    if _attached is not None:
        return _attached
    from tasks import prefect_env

    if prefect_env.api_url():
        return None
    from prefect.settings import get_current_settings

    srv = connect(get_current_settings().home)
    if srv.started:
        idle = idle_seconds()
        print(NOTE.format(ui=srv.ui, idle=f"{idle / 60:g} min" if idle >= 60 else f"{idle:g} s"), flush=True)
    os.environ["PREFECT_API_URL"] = srv.url
    import prefect.context

    prefect.context.refresh_global_settings_context()  # Prefect read its settings at import
    _attached = srv
    return srv


def ready() -> None:
    """:func:`attach` if not done yet, then wait until the server answers (no-op with the user's server)."""
    srv = attach()
    if srv is not None:
        srv.wait_ready()


# --- the server process ---------------------------------------------------------------------------------

class _Supervisor:
    """Stops uvicorn when no command has held a lease for ``idle_s``, or when the state file names
    another server and none of this one's commands is left."""

    def __init__(self, d: Path, lease: Path, idle_s: float, server: object) -> None:
        self.d, self.lease, self.idle_s, self.server = d, lease, idle_s, server
        self.t0 = time.monotonic()
        self.seen = False

    def run(self) -> None:
        idle_since: float | None = None
        while True:
            time.sleep(POLL_S)
            try:
                st = read_state(self.d)
                mine = st is not None and st["pid"] == os.getpid()
                self.seen |= mine
                free = lease_free(self.lease)
                now = time.monotonic()
                replaced = (st is not None and not mine) or (st is None and (self.seen or now - self.t0 > ORPHAN_GRACE_S))
                if replaced:
                    if free:
                        return self.stop("replaced by another server, no command left")
                    continue
                if not free:
                    idle_since = None
                    continue
                idle_since = now if idle_since is None else idle_since
                if now - idle_since >= self.idle_s and self.retire():
                    return self.stop(f"unused for {self.idle_s:g} s")
            except Exception as exc:  # noqa: BLE001 (keep watching: a crashed watcher would leave us running)
                print(f"react3d local server: watcher: {exc!r}", flush=True)

    def retire(self) -> bool:
        """Remove our state under the lock, if still unused (a command takes its lease under that
        lock, so none can pick us while we leave)."""
        with _locked(self.d / "lock", blocking=False) as got:
            if not got or not lease_free(self.lease):
                return False
            st = read_state(self.d)
            if st is not None and st["pid"] == os.getpid():
                (self.d / "state.json").unlink(missing_ok=True)
            return True

    def stop(self, why: str) -> None:
        print(f"react3d local server: stopping ({why})", flush=True)
        self.server.should_exit = True  # type: ignore[attr-defined]
        hard = threading.Timer(30.0, os._exit, args=(0,))  # a shutdown that hangs does not keep us alive
        hard.daemon = True
        hard.start()


def serve(d: Path, fd: int, lease: Path, idle_s: float) -> None:
    """Run Prefect's server (API, UI, services: what ``prefect server start`` runs) on the inherited socket."""
    sock = socket.socket(fileno=fd)
    port = sock.getsockname()[1]
    os.environ.pop("PREFECT_API_URL", None)  # the server is not a client of another one
    os.environ.update(PREFECT_SERVER_API_HOST="127.0.0.1", PREFECT_SERVER_API_PORT=str(port),
                      PREFECT_UI_API_URL=f"http://127.0.0.1:{port}/api")
    # SIGTERM / SIGINT end the process through the clean-up below (uvicorn, while it runs, shuts down
    # gracefully first and then raises the signal again)
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: sys.exit(0))
    try:
        from tasks import prefect_env

        prefect_env.configure()
        import uvicorn
        from prefect.server.api.server import create_app
        from prefect.settings import get_current_settings

        level = str(get_current_settings().server.logging_level).lower()
        server = uvicorn.Server(uvicorn.Config(create_app(final=True), log_level=level if level in
                                               {"critical", "error", "warning", "info", "debug"} else "error",
                                               lifespan="on"))
        sup = _Supervisor(d, lease, idle_s, server)
        threading.Thread(target=sup.run, name="react3d-idle-watch", daemon=True).start()
        server.run(sockets=[sock])
    finally:
        with _locked(d / "lock"):
            st = read_state(d)
            if st is not None and st["pid"] == os.getpid():
                (d / "state.json").unlink(missing_ok=True)
        lease.unlink(missing_ok=True)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog=f"python -m {MODULE}", description="react3d's local Prefect server (started by commands).")
    ap.add_argument("--folder", type=Path, required=True)
    ap.add_argument("--fd", type=int, required=True, help="Listening socket inherited from the command.")
    ap.add_argument("--lease", type=Path, required=True)
    ap.add_argument("--idle", type=float, default=IDLE_S)
    a = ap.parse_args(argv)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # a closed terminal is not a reason to stop
    serve(a.folder, a.fd, a.lease, a.idle)


if __name__ == "__main__":
    main()
