"""Self-contained HTML: the WebGL viewer (sliders per joint) plus the report tables, in one file.

No CDN, no server: the viewer script and the scene data are inlined, so the report can be mailed or
opened from a remote box's shared folder. ``react3d view`` serves the same page.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import write_text
from ..data.frames import SceneInput
from ..data.mesh import load_mesh
from ..data.parts import InteractiveScene, load_vertex_ids
from .payload import scene_payload

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


def _fmt(x: Any, d: int = 3) -> str:
    if x is None:
        return "–"
    if isinstance(x, float):
        return f"{x:.{d}f}"
    return html.escape(str(x))


def _parts_table(scene: InteractiveScene, thumbs: dict[str, list[str]]) -> str:
    rows = []
    for o in scene.objects:
        a = o.articulation
        if a.joint_type == "revolute":
            lim = f"{np.degrees(a.lower):.0f}° … {np.degrees(a.upper):.0f}°"
        else:
            lim = f"{a.lower:.3f} … {a.upper:.3f} m"
        imgs = "".join(f"<img src='{html.escape(t)}'>" for t in thumbs.get(o.object_id, []) if t.startswith("data:image/"))
        views = ", ".join(f"{v.get('frame_id')} ({v.get('iou', 0):.2f})" for v in o.top_views[:5])
        rows.append(
            f"<tr><td>{html.escape(o.object_id)}</td><td>{html.escape(o.label)}</td><td>{a.joint_type}</td>"
            f"<td>{lim}<br><small>{html.escape(a.limit_source)}</small></td><td>{_fmt(o.score, 2)}</td>"
            f"<td>{_fmt(o.cavity_depth)} m<br><small>{_fmt(o.cavity_depth_source)}</small></td>"
            f"<td>{imgs or '–'}<br><small>{html.escape(views)}</small></td></tr>"
        )
    head = "<tr><th>object</th><th>label</th><th>joint</th><th>limits</th><th>score</th><th>cavity</th><th>top views</th></tr>"
    return f"<h2>Parts ({len(scene.objects)})</h2><table>{head}{''.join(rows)}</table>"


def _metrics_table(metrics: dict[str, Any]) -> str:
    keys = ["precision", "recall", "f1", "joint_acc", "oe", "md", "pdet", "m", "mo", "mod"]
    rows = []
    for tau, vals in metrics.items():
        if not isinstance(vals, dict):
            continue
        rows.append(f"<tr><td>{html.escape(str(tau))}</td>" + "".join(f"<td>{_fmt(vals.get(k))}</td>" for k in keys) + "</tr>")
    if not rows:
        return ""
    head = "<tr><th>IoU τ</th>" + "".join(f"<th>{k}</th>" for k in keys) + "</tr>"
    return f"<h2>Metrics against ground truth</h2><table>{head}{''.join(rows)}</table>"


def _timings_table(timings: dict[str, float]) -> str:
    if not timings:
        return ""
    rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.2f}</td></tr>" for k, v in timings.items())
    return f"<h2>Timings (s)</h2><table><tr><th>stage</th><th>seconds</th></tr>{rows}</table>"


def _physics_section(scene: InteractiveScene, root: Path) -> str:
    """The physics check: a summary line per engine and, from physics_check.json, a row per joint and
    per failed probe (docs/physics.md)."""
    summary = scene.physics
    if not summary:
        return ""
    from ..physics import PhysicsCheck
    from ..physics.table import summary_line, touched_text

    head = f"<h2>Physics check: {'pass' if summary.get('passed') else 'FAIL'}</h2>"
    if summary.get("error"):
        return head + f"<p>the check could not run: {html.escape(str(summary['error']))}</p>"
    try:
        check = PhysicsCheck.model_validate(json.loads((root / str(summary.get("file", ""))).read_text()))
    except (OSError, ValueError):
        lines = "".join(f"<li>{html.escape(k)}: {html.escape(json.dumps(v))}</li>" for k, v in summary.get("engines", {}).items())
        return head + f"<ul>{lines}</ul>"
    reach = check.thresholds.get("reach_fraction", 0.9)
    lines = "".join(f"<li>{html.escape(summary_line(e, reach))}</li>" for e in check.engines)
    rows = []
    for e in check.engines:
        for j in e.joints:
            verdict = "pass" if j.passed else "FAIL: " + "; ".join(j.causes)
            rows.append(f"<tr><td>{html.escape(e.engine)}</td><td>{html.escape(j.joint)}</td><td>{html.escape(j.object_id or '–')}</td>"
                        f"<td>{100 * j.reached:.0f} %</td><td>{100 * j.penetration:.1f} cm</td>"
                        f"<td>{html.escape(touched_text(j.touched)) or '–'}</td><td>{html.escape(verdict)}</td></tr>")
    table = ("<table><tr><th>engine</th><th>joint</th><th>object</th><th>reached</th><th>penetration</th><th>touched</th>"
             f"<th>verdict</th></tr>{''.join(rows)}</table>") if rows else ""
    failed = [(e.engine, p) for e in check.engines for p in e.probes if not p.passed]
    probes = ""
    if failed:
        prow = "".join(f"<tr><td>{html.escape(eng)}</td><td>{p.kind}</td><td>{html.escape(p.object_id)}</td>"
                       f"<td>{html.escape(p.cause or '')}</td></tr>" for eng, p in failed)
        probes = f"<h3>Failed probes</h3><table><tr><th>engine</th><th>probe</th><th>object</th><th>cause</th></tr>{prow}</table>"
    return head + f"<ul>{lines}</ul>" + table + probes


REPORT_CACHE_VERSION = "1"
"""Bump when the thumbnails or the viewer payload change: part of the report cache key."""


def _file_sha(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def report_cache_key(scene: InteractiveScene, root: Path, scene_input: SceneInput | None, thumbnails: bool) -> str:
    """Content key of what the report draws: the objects, every mesh under ``meshes/``, the scan mesh and
    the frames its thumbnails use (their pose, intrinsics, image path, size and mtime). Timings, config
    and versions are not in it: they change every run and are re-read from the manifest."""
    h = hashlib.sha256(f"report|{REPORT_CACHE_VERSION}|{thumbnails}|{scene_input is not None}".encode())
    h.update(json.dumps([o.model_dump(mode="json") for o in scene.objects], sort_keys=True).encode())
    h.update(scene.background_mesh.encode())
    for p in sorted((root / "meshes").rglob("*")):
        if p.is_file():
            h.update(p.relative_to(root).as_posix().encode() + _file_sha(p).encode())
    if thumbnails and scene_input is not None and scene.objects:
        mesh_path = Path(scene.input_mesh)
        mesh_path = mesh_path if mesh_path.is_absolute() else root / mesh_path
        h.update(_file_sha(mesh_path).encode())
        used = {v["frame_id"] for o in scene.objects for v in o.top_views if "frame_id" in v}
        used |= {o.seg_frame_id for o in scene.objects if o.seg_frame_id}
        for f in scene_input.frames:
            if f.frame_id in used:
                st = f.rgb.path.stat() if f.rgb.path.is_file() else None
                h.update(f.model_dump_json().encode() + repr((st.st_size, st.st_mtime_ns) if st else None).encode())
    return h.hexdigest()


def write_report(
    manifest_path: str | Path,
    out_path: str | Path | None = None,
    scene_input: SceneInput | None = None,
    metrics: dict[str, Any] | None = None,
    thumbnails: bool = True,
    cache_dir: str | Path | None = None,
) -> Path:
    """Write ``report.html`` next to the manifest: viewer, parts with thumbnails, metrics, timings.

    ``metrics`` is the per-threshold dict (``{"0.25": {...}, "0.5": {...}}``) when GT exists;
    thumbnails need the scene input (frames) and are skipped without it. ``cache_dir``: the thumbnails
    and the decimated viewer meshes (seconds on a 490k-face scan: ray casting and simplification) are
    kept there by content (:func:`report_cache_key`), so re-converting the same scene reuses them.
    """
    manifest_path = Path(manifest_path)
    if manifest_path.is_dir():
        manifest_path = manifest_path / "scene.json"
    scene = InteractiveScene.load(manifest_path)
    root = manifest_path.parent
    cached: Path | None = None
    if cache_dir is not None:
        key = report_cache_key(scene, root, scene_input, thumbnails)
        cached = Path(cache_dir) / key[:2] / f"report-{key}.json"
        if cached.is_file():
            try:
                d = json.loads(cached.read_text())
                return _write_page(scene, root, out_path, metrics, d["thumbs"], d["payload"])
            except (OSError, ValueError, KeyError):
                pass  # unreadable: rebuild and overwrite
    thumbs: dict[str, list[str]] = {}
    if thumbnails and scene_input is not None and scene.objects:
        from .thumbnails import part_thumbnails

        mesh_path = Path(scene.input_mesh)
        mesh_path = mesh_path if mesh_path.is_absolute() else root / mesh_path
        mesh = load_mesh(mesh_path)
        parts = {}
        for o in scene.objects:
            if not o.source_vertex_ids:
                continue
            frames = [v["frame_id"] for v in o.top_views if "frame_id" in v] or ([o.seg_frame_id] if o.seg_frame_id else [])
            parts[o.object_id] = (load_vertex_ids(root / o.source_vertex_ids), frames)
        thumbs = part_thumbnails(scene_input, mesh, parts)
    payload = scene_payload(manifest_path)
    if cached is not None:
        write_text(cached, json.dumps({"thumbs": thumbs, "payload": payload}))
    return _write_page(scene, root, out_path, metrics, thumbs, payload)


def _write_page(scene: InteractiveScene, root: Path, out_path: str | Path | None, metrics: dict[str, Any] | None,
                thumbs: dict[str, list[str]], payload: dict[str, Any]) -> Path:
    payload = {**payload, "timings": scene.timings, "versions": scene.versions}  # this run's, never the cached ones
    body = (_parts_table(scene, thumbs) + (_metrics_table(metrics) if metrics else "") + _physics_section(scene, root)
            + _timings_table(scene.timings))
    page = build_viewer_html(payload, f"REACT3D · {scene.scene_id}", body, thumbs)
    return write_text(Path(out_path) if out_path else root / "report.html", page)
