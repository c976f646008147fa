"""The check as tables: per joint per engine (reached, penetration, touched, verdict), probes, and one
summary line per engine. ``rich`` renders them in a terminal; :func:`summary_line` is plain text."""

from __future__ import annotations

from typing import Any

from .result import EngineCheck, PhysicsCheck


KIND = {"revolute": "hinge", "prismatic": "slide"}


def _cm(x: float | None) -> str:
    return "–" if x is None else f"{100 * x:.1f} cm"


def touched_text(touches: list[Any], n: int = 3) -> str:
    return ", ".join(f"{t.body} {_cm(t.depth)}" for t in touches[:n]) + (" …" if len(touches) > n else "")


def summary_line(e: EngineCheck, reach: float = 0.9) -> str:
    """``mujoco: 8/10 joints pass, 9/10 reach >= 90 %, max penetration 0.4 cm, 0 unstable; cavities 4/4
    free, fronts 10/10 blocked; 12.3 s``."""
    s = e.summary(reach)
    if e.status != "ok":
        return f"{e.engine}: {e.status} ({e.reason})"
    line = (f"{e.engine} {e.version or ''}: {s['passed']}/{s['joints']} joints pass, {s['reached']}/{s['joints']} reach "
            f">= {100 * reach:.0f} %, max penetration {_cm(s['max_penetration'])}, {s['unstable']} unstable")
    if s["cavities"] or s["fronts"]:
        line += f"; cavities {s['cavities_free']}/{s['cavities']} free, fronts {s['fronts_blocked']}/{s['fronts']} blocked"
    if e.rest is not None:
        line += f"; at rest {e.rest.moving_contacts} contacts on moving parts (deepest {_cm(e.rest.deepest)})"
    return line + f"; {e.seconds:.1f} s"


def render(check: PhysicsCheck, console: Any = None, show_probes: bool = True) -> None:
    """Print the joint table, the failed probes and the summary lines with ``rich``."""
    from rich.console import Console
    from rich.table import Table

    console = console or Console()
    reach = check.thresholds.get("reach_fraction", 0.9)
    table = Table(title=f"physics check · {check.scene_id}", show_lines=False)
    for col, kw in [("engine", {}), ("joint", {}), ("object", {}), ("type", {}), ("reached", {"justify": "right"}),
                    ("t90", {"justify": "right"}), ("penetration", {"justify": "right"}), ("touched", {"max_width": 48}),
                    ("verdict", {"max_width": 60})]:
        table.add_column(col, **kw)
    for e in check.engines:
        if e.status != "ok":
            table.add_row(e.engine, "–", "–", "–", "–", "–", "–", "–", f"[yellow]{e.status}[/]: {e.reason}")
            continue
        for j in e.joints:
            verdict = "[green]pass[/]" if j.passed else "[red]FAIL[/] " + "; ".join(j.causes)
            table.add_row(e.engine, j.joint, j.object_id or "–", KIND[j.joint_type], f"{100 * j.reached:.0f} %",
                          "–" if j.time_to_reach is None else f"{j.time_to_reach:.2f} s", _cm(j.penetration),
                          touched_text(j.touched) or "–", verdict)
    console.print(table)
    if show_probes:
        failed = [(e.engine, p) for e in check.engines for p in e.probes if not p.passed]
        if failed:
            pt = Table(title="failed probes")
            for col in ("engine", "probe", "object", "cause"):
                pt.add_column(col)
            for engine, p in failed:
                pt.add_row(engine, p.kind, p.object_id, p.cause or "")
            console.print(pt)
    for e in check.engines:
        console.print(summary_line(e, reach))
    verdict = "[green]PASS[/]" if check.passed else "[red]FAIL[/]"
    console.print(f"physics check: {verdict} ({check.seconds:.1f} s)")
