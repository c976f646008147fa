"""A rich table of a converted scene: parts, joints, limits, cavities, timings and metrics."""

from __future__ import annotations

from pathlib import Path

from rich.console import Console
from rich.table import Table


def print_summary(console: Console, manifest_path: str, metrics: dict | None = None) -> None:
    from react3d_core.data.parts import InteractiveScene

    m = InteractiveScene.load(manifest_path)
    t = Table(title=f"{m.scene_id}: {len(m.objects)} movable parts")
    for c in ("part", "label", "joint", "axis", "limits", "cavity (m)"):
        t.add_column(c)
    for o in m.objects:
        a = o.articulation
        lim = f"[{a.lower:.2f}, {a.upper:.2f}] {'rad' if a.joint_type == 'revolute' else 'm'}"
        t.add_row(o.object_id, o.label, a.joint_type, " ".join(f"{x:+.2f}" for x in a.axis), lim,
                  "–" if o.cavity_depth is None else f"{o.cavity_depth:.3f}")
    console.print(t)
    if m.timings:
        console.print("timings (s): " + ", ".join(f"{k} {v:.1f}" for k, v in m.timings.items()))
    if metrics and "aggregate" in metrics:
        mt = Table(title="accuracy against ground truth")
        for c in ("IoU τ", "precision", "recall", "F1", "joint acc", "OE (°)", "MD (m)", "+MOD"):
            mt.add_column(c, justify="right")
        f = lambda x: "–" if x is None else f"{x:.3f}"  # noqa: E731
        for tau, r in metrics["aggregate"].items():
            mt.add_row(tau, f(r["precision"]), f(r["recall"]), f(r["f1"]), f(r["joint_acc"]), f(r["oe"]), f(r["md"]), f(r["mod"]))
        console.print(mt)
    root = Path(manifest_path).parent
    if m.physics:
        console.print(physics_line(m.physics) + f"  (details: {root / m.physics.get('file', 'physics_check.json')}, "
                      f"`react3d check {root}` for all engines)")
    for name, rel in sorted(m.exports.items()):
        console.print(f"{name}: {root / rel}")
    if (root / "report.html").exists():
        console.print(f"[bold]report:[/bold] {root / 'report.html'}  (open in a browser, or `react3d view {root}`)")


def physics_line(summary: dict) -> str:
    """One line from the manifest's ``physics`` summary: per engine joints passing and probes."""
    if summary.get("error"):
        return f"[yellow]physics check could not run[/]: {summary['error']}"
    parts = []
    for engine, e in summary.get("engines", {}).items():
        if e.get("status") != "ok":
            parts.append(f"{engine} {e.get('status')}")
            continue
        parts.append(f"{engine} {e['passed']}/{e['joints']} joints pass, cavities {e['cavities_free']}/{e['cavities']} free, "
                     f"fronts {e['fronts_blocked']}/{e['fronts']} blocked")
    verdict = "[green]pass[/]" if summary.get("passed") else "[red]FAIL[/]"
    return f"physics check {verdict}: " + "; ".join(parts)
