"""Drive the viewer and the static report in headless Chromium: a slider moves its part, nothing else."""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.browser

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
if CHROMIUM is None:
    pytest.skip("Debian chromium not installed (apt-get install chromium)", allow_module_level=True)



def _shot(page) -> np.ndarray:
    from PIL import Image

    page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)


def _check_slider_moves_only_its_part(page, object_id: str) -> None:
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.wait_for_function("window.react3d && window.react3d.ready")
    before = _shot(page)
    slider = page.locator(f"#slider-{object_id}")
    slider.focus()
    slider.press("End")  # the keyboard moves the range input to its upper limit, firing 'input'
    after = _shot(page)
    q = float(slider.input_value())
    assert q > 0, "the slider did not move"
    canvas = page.locator("#r3d-canvas").bounding_box()
    b0 = page.evaluate(f"window.react3d.screenBox('{object_id}', 0)")
    b1 = page.evaluate(f"window.react3d.screenBox('{object_id}', {q})")
    x0 = int(canvas["x"] + min(b0[0], b1[0])) - 12
    y0 = int(canvas["y"] + min(b0[1], b1[1])) - 12
    x1 = int(canvas["x"] + max(b0[2], b1[2])) + 12
    y1 = int(canvas["y"] + max(b0[3], b1[3])) + 12
    cx0, cy0 = int(canvas["x"]), int(canvas["y"])
    cx1, cy1 = int(canvas["x"] + canvas["width"]), int(canvas["y"] + canvas["height"])
    diff = np.abs(after - before).sum(-1) > 30
    view = np.zeros_like(diff)
    view[cy0:cy1, cx0:cx1] = True
    region = np.zeros_like(diff)
    region[max(y0, 0):y1, max(x0, 0):x1] = True
    changed_in = (diff & region).sum()
    changed_out = (diff & view & ~region).sum()
    assert not errors, errors
    assert changed_in > 200, f"the part's region did not change ({changed_in} px)"
    assert changed_out <= 0.01 * changed_in, f"{changed_out} px changed outside the part's region"


def test_viewer_slider_moves_one_part(browser, toy_scene):
    from flows.viewer_server import serve_in_background

    server, url = serve_in_background(toy_scene)
    try:
        page = browser.new_page(viewport={"width": 1200, "height": 800})
        page.goto(url)
        _check_slider_moves_only_its_part(page, "obj_000")
        page.locator("button.r3d-name", has_text="obj_001").click()
        assert "prismatic" in page.locator("#r3d-info").inner_text()
        page.close()
    finally:
        server.shutdown()


def test_report_from_disk_slider_moves_one_part(browser, toy_scene, tmp_path: Path):
    from react3d_core.viewer import write_report

    report = write_report(toy_scene, tmp_path / "report.html")
    page = browser.new_page(viewport={"width": 1200, "height": 800})
    page.goto(report.as_uri())
    _check_slider_moves_only_its_part(page, "obj_001")
    page.close()
