"""``report.html`` beside a converted scene: the viewer page (:mod:`.page`) with the parts (thumbnails of
their best views), the metrics against ground truth and the stage timings.

Thumbnails and the viewer payload are cached by content (:func:`report_cache_key`), so re-converting the
same scene reuses them.
"""

from __future__ import annotations

import hashlib
import html
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import write_text
from ..data.frames import SceneInput
from ..data.mesh import load_mesh
from ..data.parts import InteractiveScene, load_vertex_ids
from .page import build_viewer_html
from .payload import scene_payload


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
