"""``react3d demo --out DIR``: the built-in demo scene, converted end to end with the default settings."""

from __future__ import annotations

import argparse

HELP = "Generate the built-in demo scene and convert it (weight-free heuristic perception, embedded Prefect)."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="demo_out", help="Output folder: scene/ (the input) and result/ (the conversion).")
    p.add_argument("--perception", choices=["heuristic", "oracle"], default="heuristic",
                   help="heuristic (default, weight-free) or oracle (ground-truth masks with noise).")


def run(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from flows.commands._console import wide_console

    from react3d_core.synthetic import demo_scene

    from ._runconfig import run_with_progress
    from .summary import print_summary

    from react3d_core.atomic import check_output_dir

    console = wide_console()
    out = Path(args.out)
    scene = out / "scene"
    if not (scene / "synth_meta.json").exists():
        check_output_dir(scene, kind="synth")  # a folder of the user's named demo_out/scene is never replaced
    check_output_dir(out / "result", (scene,), kind="scene")
    from flows import local_server

    local_server.attach()  # a server that has to start does so while the demo scene is made
    if not (scene / "synth_meta.json").exists():
        with console.status("generating the demo scene (synthetic kitchen with ground truth)"):
            demo_scene(scene)
    # synthetic captures are already sparse (a frame every few cm of camera motion): use every frame
    cfg = {"perception": {"backend": args.perception}, "frames": {"stride": 1}}
    manifest = run_with_progress(str(scene), str(out / "result"), cfg, f"converting the demo scene ({args.perception})")
    from react3d_core.data.parts import InteractiveScene

    m = InteractiveScene.load(manifest)
    metrics = None
    mpath = Path(manifest).parent / "metrics.json"
    if mpath.exists():
        metrics = json.loads(mpath.read_text())
    print_summary(console, manifest, metrics)
    console.print(f"[green]done[/green]: {len(m.objects)} parts in {m.timings.get('total', 0):.1f} s")
    return 0
