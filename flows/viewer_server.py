"""A small local HTTP server for ``react3d view``: the viewer page at ``/``, the output folder beside it.

The page is the same self-contained viewer as ``report.html``; serving it lets a user on a remote GPU
box open it through an SSH tunnel (``ssh -L 8080:127.0.0.1:8080 box``) without copying files.
"""

from __future__ import annotations

import functools
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

from react3d_core.data import InteractiveScene
from react3d_core.viewer import build_viewer_html, scene_payload


class _Handler(SimpleHTTPRequestHandler):
    page: bytes = b""

    def do_GET(self) -> None:  # noqa: N802 - http.server API
        if self.path in ("/", "/index.html"):
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.send_header("Content-Length", str(len(self.page)))
            self.end_headers()
            self.wfile.write(self.page)
            return
        super().do_GET()

    def log_message(self, format: str, *args: object) -> None:  # noqa: A002 - quiet server
        return


def make_viewer_server(out_dir: str | Path, host: str = "127.0.0.1", port: int = 8080) -> tuple[ThreadingHTTPServer, str]:
    """Build (not start) the server; port 0 picks a free port. Returns (server, url)."""
    out_dir = Path(out_dir)
    manifest = out_dir / "scene.json" if out_dir.is_dir() else out_dir
    scene = InteractiveScene.load(manifest)
    page = build_viewer_html(scene_payload(manifest), f"REACT3D · {scene.scene_id}").encode("utf-8")
    handler = type("ViewerHandler", (_Handler,), {"page": page})
    server = ThreadingHTTPServer((host, port), functools.partial(handler, directory=str(manifest.parent)))
    return server, f"http://{host}:{server.server_address[1]}/"


def serve_in_background(out_dir: str | Path, host: str = "127.0.0.1", port: int = 0) -> tuple[ThreadingHTTPServer, str]:
    """Start the viewer server on a daemon thread (tests, notebooks). Call ``server.shutdown()`` to stop."""
    server, url = make_viewer_server(out_dir, host, port)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, url
