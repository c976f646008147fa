"""``react3d view OUT``: serve the interactive viewer of a converted scene on 127.0.0.1."""

from __future__ import annotations

import argparse

HELP = "Open a converted scene in the browser: a slider per joint, open/close all, toggles, click for details."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", help="Output folder of `react3d convert` (holds scene.json), or its s3://... output "
                               "(read through its pointer, every file checked against it).")
    p.add_argument("--port", type=int, default=8080, help="Port (0 = any free port).")
    p.add_argument("--host", default="127.0.0.1", help="Address to bind (default loopback; tunnel with ssh -L).")


def run(args: argparse.Namespace) -> int:
    from flows.viewer_server import make_viewer_server
    from tasks import storage

    out = str(storage.fetch_output(args.out)) if storage.is_remote(args.out) else args.out
    server, url = make_viewer_server(out, args.host, args.port)
    print(f"REACT3D viewer at {url}  (Ctrl-C to stop; static report: {url}report.html if written)")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0
