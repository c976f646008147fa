"""Screenshots of a converted scene's report.html (closed, all open, one part selected) for the docs.

    python3 scripts/screenshots.py demo_out/result docs/images
Needs playwright and a Chromium (the Debian one: apt-get install chromium).
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-sandbox"]


def main(result: str, out_dir: str) -> int:
    from playwright.sync_api import sync_playwright

    report = Path(result).resolve() / "report.html"
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, args=ARGS)
        page = b.new_page(viewport={"width": 1400, "height": 900})
        page.goto(report.as_uri())
        page.wait_for_function("window.react3d && window.react3d.ready", timeout=120_000)
        page.screenshot(path=str(out / "report_closed.png"))
        page.evaluate("window.react3d.openAll()")
        page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        page.screenshot(path=str(out / "report_open.png"))
        page.screenshot(path=str(out / "report_full.png"), full_page=True)
        # the live viewer (react3d view) on 127.0.0.1, one part selected and half open
        sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
        from flows.viewer_server import serve_in_background

        server, url = serve_in_background(result)
        try:
            page = b.new_page(viewport={"width": 1400, "height": 900})
            page.goto(url)
            page.wait_for_function("window.react3d && window.react3d.ready", timeout=120_000)
            first = page.evaluate("window.react3d.objectIds[0]")
            page.evaluate(f"window.react3d.select('{first}')")
            page.evaluate(f"window.react3d.setJoint('{first}', 0.5)")
            page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
            page.screenshot(path=str(out / "viewer_selected.png"))
        finally:
            server.shutdown()
        b.close()
    print(f"wrote {out}/report_closed.png, report_open.png, report_full.png, viewer_selected.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(*sys.argv[1:3]))
