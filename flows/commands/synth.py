"""``react3d synth --seed N --out DIR``: write a synthetic scene with ground truth (ScanNet++ iPhone layout)."""

from __future__ import annotations

import argparse

HELP = "Generate a synthetic scene with GT joints: procedural room, scene-synthesizer kitchen or any URDF."


def _pixel_shift(text: str) -> tuple[float, float]:
    """``DX,DY`` -> (dx, dy); a clear argparse error otherwise."""
    try:
        dx, dy = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected DX,DY in pixels (e.g. 2,1), got {text!r}") from None
    return dx, dy


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, help="Output scene folder (replaced atomically).")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--source", default="procedural", choices=["procedural", "scene-synthesizer", "urdf"])
    p.add_argument("--kind", default=None, choices=["kitchen", "wardrobe", "dresser", "room_door", "mixed", "sliding", "large_kitchen",
                                                   "furniture", "appliances", "glass", "dark"],
                   help="Procedural room type (default: chosen by seed; only when asked: sliding = sliding-door sideboard "
                        "and wardrobe, large_kitchen = an L of two full walls, 32-52 parts; free-standing pieces against walls "
                        "and free in the room beside clutter: furniture = desks, nightstands, chests, cabinets, wardrobes, "
                        "sideboards; appliances = fridge, freezer, dishwasher, cooker, microwave, washing machine; glass = "
                        "glass-panel doors; dark = black and dark-wood fronts).")
    p.add_argument("--frames", type=int, default=60, help="Number of RGB-D frames to render.")
    p.add_argument("--urdf", default=None, help="Articulated URDF for --source urdf.")
    p.add_argument("--up", default="z", choices=["z", "y", "x", "-z", "-y", "-x"],
                   help="--source urdf: the asset's up axis, turned to the scene's +z (many exporters write y-up).")
    p.add_argument("--scale", type=float, default=1.0,
                   help="--source urdf: multiply the asset's lengths (and prismatic limits) by this (0.01 for centimetres).")
    p.add_argument("--preview", action="store_true", help="Also write preview.png (frames beside GT part ids).")
    p.add_argument("--edge", type=float, default=None, help="Furniture triangle size in metres (default 0.03 procedural, 0.05 others).")
    p.add_argument("--mesh", default="clean", choices=["clean", "laser", "tsdf"],
                   help="Written scan mesh: the generated geometry, a laser-like 5 mm remesh (1.5 mm range noise) or a "
                        "1 cm TSDF of the scene's own noisy depth + colour frames; GT is transferred to it.")
    p.add_argument("--realism", default="photo", choices=["plain", "photo"],
                   help="RGB renderer: photo (materials, highlights, light falloff, exposure, blur) or plain flat shading.")
    p.add_argument("--misregister", type=_pixel_shift, default=(0.0, 0.0), metavar="DX,DY",
                   help="Shift colour against depth by DX,DY pixels of the RGB image, like a Kinect (photo only).")
    p.add_argument("--depth-dropout", default="none", choices=["none", "dark"],
                   help="dark: no depth on dark surfaces (and at grazing angles, and near the mirror direction of glossy ones), "
                        "like ToF / structured-light sensors, in the depth frames and the laser / TSDF mesh made from them.")


def run(args: argparse.Namespace) -> int:
    import json
    import time
    from pathlib import Path

    from flows.commands._console import wide_console

    from react3d_core.synthetic import generate_scene

    from react3d_core import __version__
    from react3d_core.atomic import OUTPUT_MARKER, check_output_dir
    from react3d_core.errors import ConfigError

    if args.realism == "plain" and args.misregister != (0.0, 0.0):
        raise ConfigError("--misregister shifts the photo renderer's colour: it needs --realism photo")
    if args.source != "urdf" and (args.up != "z" or args.scale != 1.0):
        raise ConfigError("--up and --scale apply to --source urdf only")
    if not (args.scale > 0 and args.scale < float("inf")):
        raise ConfigError(f"--scale must be a positive number, got {args.scale}")
    check_output_dir(args.out, (args.urdf,) if args.urdf else (), kind="synth")  # never replace the user's files
    console = wide_console()
    t0 = time.perf_counter()
    with console.status(f"rendering {args.frames} frames ({args.source}, seed {args.seed})"):
        out = generate_scene(args.out, source=args.source, seed=args.seed, n_frames=args.frames,
                             urdf_path=args.urdf, kind=args.kind, edge=args.edge, mesh=args.mesh,
                             realism=args.realism, misregister=args.misregister, up=args.up, scale=args.scale,
                             depth_dropout=args.depth_dropout)
    # deterministic (hidden files stay out of scan fingerprints): lets a later synth replace this folder
    (Path(out) / OUTPUT_MARKER).write_text(json.dumps({"react3d": __version__, "kind": "synth"}))
    meta = json.loads((Path(out) / "synth_meta.json").read_text())
    if args.preview:
        from react3d_core.synthetic.preview import write_preview

        console.print(f"preview: {write_preview(out)}")
    for w in meta.get("up_warnings", []):
        console.print(f"[yellow]warning:[/yellow] {w}", highlight=False)
    types = [p["type"] for p in meta["parts"]]
    console.print(f"[green]wrote[/green] {out}: {meta['kind']}, {meta['mesh']['kind']} mesh, {meta['faces']} faces, "
                  f"{meta['realism']} images, {meta['n_frames']} frames, "
                  f"{len(types)} joints ({types.count('revolute')} revolute, {types.count('prismatic')} prismatic) "
                  f"in {time.perf_counter() - t0:.1f} s")
    return 0
