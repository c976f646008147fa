"""The viewer page: one self-contained HTML document (WebGL viewer, a slider per joint, optional tables)
under a hash-based Content-Security-Policy. ``report.html`` (:mod:`.report`) and ``react3d view`` both
serve it.

No CDN, no server: the viewer script and the scene data are inlined, so the page can be mailed or
opened from a remote box's shared folder.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
from importlib import resources
from typing import Any

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,sans-serif;margin:0;color:#222;background:#fafafa}
header{padding:10px 16px;background:#1f2937;color:#fff}header h1{font-size:18px;margin:0}
#r3d-app{display:flex;height:72vh;min-height:420px;border-bottom:1px solid #ddd}
#r3d-stage{position:relative;flex:1}#r3d-canvas{width:100%;height:100%;display:block}
#r3d-labels{position:absolute;left:0;top:0;pointer-events:none}
.r3d-label{position:absolute;transform:translate(-50%,-50%);font-size:11px;background:rgba(255,255,255,.8);padding:0 3px;border-radius:3px}
#r3d-side{width:320px;overflow:auto;padding:8px 10px;background:#fff;border-left:1px solid #ddd;font-size:13px}
.r3d-row{display:flex;align-items:center;gap:6px;margin:3px 0}.r3d-row input{flex:1}
.r3d-name{font-size:12px;min-width:92px;text-align:left;border:1px solid #ccc;background:#f3f4f6;border-radius:4px;cursor:pointer}
#r3d-info{margin-top:8px;padding:6px;background:#f3f4f6;border-radius:4px;line-height:1.45}
.r3d-thumb{height:80px;margin:4px 4px 0 0;border:1px solid #ccc}
main{padding:8px 16px}table{border-collapse:collapse;font-size:13px;margin:6px 0 16px}
td,th{border:1px solid #ddd;padding:3px 8px;text-align:left;vertical-align:middle}th{background:#f3f4f6}
td img{height:72px;margin-right:3px}
#r3d-toggles{margin:6px 0}#r3d-status{color:#666;margin-top:6px}
"""

_APP = """
<div id="r3d-app">
  <div id="r3d-stage"><canvas id="r3d-canvas"></canvas><div id="r3d-labels"></div></div>
  <div id="r3d-side">
    <div><button id="r3d-open">open all</button> <button id="r3d-close">close all</button></div>
    <div id="r3d-toggles">
      <label><input type="checkbox" id="r3d-show-background">background</label>
      <label><input type="checkbox" id="r3d-show-cavities">cavities</label>
      <label><input type="checkbox" id="r3d-show-axes">joint axes</label>
      <label><input type="checkbox" id="r3d-show-labels">labels</label>
    </div>
    <div id="r3d-joints"></div>
    <div id="r3d-info"></div>
    <div id="r3d-status"></div>
  </div>
</div>
"""


def _viewer_js() -> str:
    return resources.files("react3d_core.viewer").joinpath("assets/viewer.js").read_text(encoding="utf-8")


def _json_for_script(obj: Any) -> str:
    # '</' would end the <script> element early.
    return json.dumps(obj, separators=(",", ":")).replace("</", "<\\/")


def _sha256_source(text: str) -> str:
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode() + "'"


def content_security_policy(scripts: list[str], styles: list[str]) -> str:
    """The page's CSP: only these exact inline scripts and styles run (by sha256), images only inline
    (``data:``), nothing loaded or sent anywhere: injected markup can neither run nor phone home."""
    return ("default-src 'none'; "
            f"script-src {' '.join(_sha256_source(s) for s in scripts)}; "
            f"style-src {' '.join(_sha256_source(s) for s in styles)}; "
            "img-src data:; base-uri 'none'; form-action 'none'")


def build_viewer_html(payload: dict[str, Any], title: str, body: str = "", thumbs: dict[str, list[str]] | None = None) -> str:
    """One HTML page: viewer + optional extra body (tables), under a hash-based Content-Security-Policy."""
    data = f"window.REACT3D_SCENE={_json_for_script(payload)};window.REACT3D_THUMBS={_json_for_script(thumbs or {})};"
    viewer = _viewer_js()
    csp = content_security_policy([data, viewer], [_CSS])
    return (
        "<!doctype html><html><head><meta charset='utf-8'>"
        f"<meta http-equiv='Content-Security-Policy' content=\"{csp}\">"
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
        f"<header><h1>{html.escape(title)}</h1></header>{_APP}<main>{body}</main>"
        f"<script>{data}</script>"
        f"<script>{viewer}</script></body></html>"
    )
