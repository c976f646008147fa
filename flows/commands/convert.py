"""``react3d convert SCENE --out OUT``: one scan -> interactive scene, with an embedded Prefect."""

from __future__ import annotations

import argparse

from ._runconfig import add_pipeline_arguments

HELP = "Convert one scan (ScanNet++ iPhone/DSLR, prepared, mesh + transforms.json) into an interactive scene."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", help="Scene folder, or its URL (s3://bucket/scans/scene: downloaded into this "
                                 "machine's bounded scan cache, REACT3D_SCAN_CACHE_GB).")
    p.add_argument("--out", required=True, help="Output folder: new, empty, or a previous react3d output (replaced atomically when the run finishes).")
    add_pipeline_arguments(p)


def run(args: argparse.Namespace) -> int:
    from tasks import scan_cache, storage

    if storage.is_remote(args.scene):  # kept in the scan cache (not evicted) until the conversion ends
        with scan_cache.local_scene(args.scene) as local:
            return _run(args, str(local))
    return _run(args, args.scene)


def _run(args: argparse.Namespace, scene: str) -> int:
    from flows.commands._console import wide_console

    from ._runconfig import pipeline_overrides, precheck_scene, run_with_progress
    from .summary import print_summary

    from react3d_core.atomic import check_output_dir

    cfg = pipeline_overrides(args)
    check_output_dir(args.out, (scene,), kind="scene")  # before Prefect starts: one line, nothing touched
    console = wide_console()
    console.print(precheck_scene(scene, cfg), markup=False, highlight=False)  # "kept N of M frames: why"
    manifest = run_with_progress(scene, args.out, cfg, f"converting {args.scene}")
    print_summary(console, manifest)
    return 0
