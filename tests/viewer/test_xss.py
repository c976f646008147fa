"""Manifest text (labels, frame ids, limit sources) never runs as script in the viewer
or the report, and the page's Content-Security-Policy blocks script it did not ship."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
if CHROMIUM is None:
    pytest.skip("Debian chromium not installed (apt-get install chromium)", allow_module_level=True)


# each one sets a global when its markup is parsed as HTML instead of shown as text
FRAME = 'frame<img src=x onerror="window.__pwned=(window.__pwned||[]).concat(\'frame\')">'
LABEL = 'door<img src=x onerror="window.__pwned=(window.__pwned||[]).concat(\'label\')">'
SOURCE = 'cap<svg onload="window.__pwned=(window.__pwned||[]).concat(\'limit\')">'
TITLE = 'toy</title><script>window.__pwned=["title"]</script>'


@pytest.fixture(scope="module")
def hostile_scene(toy_scene: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("hostile") / "scene"
    shutil.copytree(toy_scene, out)
    m = json.loads((out / "scene.json").read_text())
    m["scene_id"] = TITLE
    for o in m["objects"]:
        o["label"] = LABEL
        o["top_views"] = [{"frame_id": FRAME, "iou": 0.9}]
        o["seg_frame_id"] = FRAME
        o["articulation"]["limit_source"] = SOURCE
    (out / "scene.json").write_text(json.dumps(m))
    return out


def _open(browser, url: str):  # noqa: ANN001, ANN202
    page = browser.new_page(viewport={"width": 1100, "height": 800})
    page.add_init_script("window.__csp = []; document.addEventListener('securitypolicyviolation',"
                         " e => window.__csp.push(e.violatedDirective + ' ' + e.blockedURI));")
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    page.wait_for_function("window.react3d && window.react3d.ready")
    return page, errors


def _click_every_part_and_check(page, errors: list[str]) -> None:  # noqa: ANN001
    for oid in page.evaluate("window.react3d.objectIds"):
        page.evaluate(f"window.react3d.select('{oid}')")
        info = page.locator("#r3d-info")
        text = info.inner_text()
        assert FRAME in text and LABEL in text and SOURCE in text  # shown, as text
        assert info.locator("img, svg, script").count() == 0
    page.wait_for_timeout(300)  # give an injected onerror/onload the chance to fire
    assert page.evaluate("window.__pwned") is None
    assert page.evaluate("window.__csp") == []  # the page's own scripts and style all pass the CSP
    assert errors == []


def test_report_shows_hostile_names_as_text(hostile_scene: Path, browser) -> None:  # noqa: ANN001
    from react3d_core.viewer import write_report

    report = write_report(hostile_scene, thumbnails=False)
    page, errors = _open(browser, report.as_uri())
    assert page.title() == "REACT3D · " + TITLE
    assert page.locator("main table").first.inner_text().count(LABEL) == 2  # the parts table escapes too
    _click_every_part_and_check(page, errors)
    page.close()


def test_view_server_shows_hostile_names_as_text(hostile_scene: Path, browser) -> None:  # noqa: ANN001
    from flows.viewer_server import serve_in_background

    server, url = serve_in_background(hostile_scene)
    try:
        page, errors = _open(browser, url)
        _click_every_part_and_check(page, errors)
        page.close()
    finally:
        server.shutdown()


def test_csp_blocks_script_the_page_did_not_ship(hostile_scene: Path, browser) -> None:  # noqa: ANN001
    """Second line of defence: markup injected by any future bug may not run inline handlers or scripts."""
    from react3d_core.viewer import write_report

    report = write_report(hostile_scene, thumbnails=False)
    page, _ = _open(browser, report.as_uri())
    page.evaluate("""() => {
        document.getElementById('r3d-info').innerHTML = `<img src=x onerror="window.__pwned=['handler']">`;
        const s = document.createElement('script'); s.textContent = "window.__pwned=['script']";
        document.body.append(s);
    }""")
    page.wait_for_timeout(300)
    assert page.evaluate("window.__pwned") is None
    assert any("script-src" in v for v in page.evaluate("window.__csp"))
    page.close()
