"""``react3d export OUT``: re-export a converted scene (its scene.json) to URDF / USD / MJCF without recomputing."""

from __future__ import annotations

import argparse

HELP = "Export a converted scene (OUT/scene.json) to simulator formats: URDF, USD, MJCF (textures, collisions, inertia)."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", help="Output folder of a conversion (holds scene.json), or the scene.json itself.")
    p.add_argument("--formats", default=None, help="Comma-separated formats (urdf, usd, mjcf); default: the config's export.formats. "
                                                   "OUT/export is replaced as a whole and then holds exactly these (collisions come from the cache).")
    p.add_argument("--config", default=None, help="Pipeline config JSON; its 'export' section is used.")
    p.add_argument("--ros-package", action="store_true", help="Also write a ROS 2 description package (package:// paths).")
    p.add_argument("--texel-per-m", type=float, default=None, help="Texture budget override (texels per metre).")
    p.add_argument("--to", default=None, help="For an s3://... OUT: a new local folder that receives the output "
                                              "(read through its pointer, checked against it) and the export.")


def _local_copy(url: str, to: str | None) -> object:
    """The verified remote output ``url`` copied into the new local folder ``to`` (exports write there)."""
    import shutil
    from pathlib import Path

    from react3d_core.errors import InputError
    from tasks import storage

    if not to:
        raise InputError(url, "is a remote output: add --to DIR, a new local folder to export into")
    dest = Path(to)
    if dest.exists():
        raise InputError(dest, "exists; --to must name a new folder")
    src = storage.fetch_output(url.removesuffix("/scene.json"))
    tmp = dest.with_name(f".{dest.name}.tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    shutil.copytree(src, tmp)
    tmp.rename(dest)
    return dest


def run(args: argparse.Namespace) -> int:
    from react3d_core.config import PipelineConfig
    from react3d_core.errors import ConfigError
    from react3d_core.export import export_scene

    from pathlib import Path

    from react3d_core.atomic import is_react3d_output
    from react3d_core.errors import InputError

    from tasks import storage

    if storage.is_remote(args.out):
        args.out = str(_local_copy(args.out, args.to))
    elif args.to:
        raise InputError(args.to, "--to is for an s3://... output; a local OUT is exported in place")
    folder = Path(args.out)
    folder = folder.parent if folder.name == "scene.json" and not folder.is_dir() else folder
    if not is_react3d_output(folder, "scene"):
        # export replaces folders under OUT/export: only inside an output react3d wrote
        raise InputError(folder, "is not a react3d conversion output (no .react3d-output marker); "
                                 "give the --out folder of a `react3d convert` run")
    cfg = PipelineConfig.from_file(args.config).export if args.config else PipelineConfig().export
    updates: dict = {}
    if args.ros_package:
        updates["ros_package"] = True
    if args.texel_per_m is not None:
        if args.texel_per_m <= 0:
            raise ConfigError("--texel-per-m must be > 0")
        updates["texel_per_m"] = args.texel_per_m
    cfg = cfg.model_copy(update=updates)
    formats = tuple(f.strip().lower() for f in args.formats.split(",") if f.strip()) if args.formats else cfg.formats
    for fmt, path in export_scene(args.out, formats=formats, config=cfg).items():
        print(f"{fmt}: {path}")
    return 0
