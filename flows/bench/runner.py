"""The benchmark runner behind ``react3d bench``: generate (if needed), convert, time, measure memory
and evaluate a benchmark set (docs/evaluation.md).

Each scene runs in a fresh spawned process so its peak RSS is its own (ru_maxrss never goes down).
Set files ship with the package (``flows/bench/sets/*.json``), so a non-editable install finds them too.
"""

from __future__ import annotations

import glob as globmod
import json
import multiprocessing as mp
import os
import resource
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
from importlib import resources
from pathlib import Path
from typing import Any

from react3d_core.errors import InputError

SETS_DIR = Path(str(resources.files("flows.bench") / "sets"))


def load_spec(spec: str, out_dir: Path, frames: int | None = None) -> list[dict[str, Any]]:
    """Scene entries {name, scene_dir | (source, kind, seed, n_frames)} from a set file or a glob."""
    cand = Path(spec)
    if not cand.suffix and not any(c in spec for c in "*?[") and (SETS_DIR / f"{spec}.json").is_file():
        cand = SETS_DIR / f"{spec}.json"
    if cand.suffix == ".json" and cand.is_file():
        try:
            d = json.loads(cand.read_text())
            n = frames or int(d.get("n_frames", 60))
            out = []
            for e in d["scenes"]:
                src, seed, kind = e.get("source", "procedural"), int(e["seed"]), e.get("kind")
                # scan realism (generate_scene's mesh / realism / misregister) is part of the scene's name
                opts = {k: e[k] for k in ("mesh", "realism", "misregister", "depth_dropout", "decimate") if k in e}
                name = "_".join([f"{src}_{kind or 'any'}_{seed}"] + [str(opts[k]) for k in ("mesh", "realism") if k in opts]
                                + ([f"dropout-{opts['depth_dropout']}"] if opts.get("depth_dropout", "none") != "none" else [])
                                + ([f"d{float(opts['decimate']):g}"] if "decimate" in opts else []))
                out.append({"name": name, "source": src, "kind": kind, "seed": seed, "n_frames": int(e.get("n_frames", n)),
                            "scene_dir": str(out_dir / "scenes" / f"{name}_f{int(e.get('n_frames', n))}"), "synth": opts})
            return out
        except (KeyError, TypeError, ValueError, json.JSONDecodeError) as exc:
            raise InputError(cand, f"bad benchmark set ({exc.__class__.__name__}: {exc})") from None
    dirs = sorted(p for p in globmod.glob(spec) if Path(p).is_dir())
    if not dirs:
        raise InputError(spec, "neither a benchmark set file nor a glob matching scene folders")
    return [{"name": Path(p).name, "scene_dir": p} for p in dirs]


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB


@contextmanager
def cold_cache(parent: str | Path) -> Iterator[Path]:
    """Run inside an empty object store and Prefect result storage made fresh under ``parent``.

    Content keys make a second run of the same scene a cache hit: timings of a benchmark that follows a
    check run would otherwise be those of a re-run. The folder is a new one this run made (a unique
    name), so removing it afterwards can never remove anything else that lives under ``parent``.
    """
    from prefect.settings import PREFECT_LOCAL_STORAGE_PATH, temporary_settings

    Path(parent).mkdir(parents=True, exist_ok=True)
    root = Path(tempfile.mkdtemp(prefix=".cold-cache-", dir=parent))
    old = os.environ.get("REACT3D_CACHE")
    os.environ["REACT3D_CACHE"] = str(root / "react3d")
    try:
        with temporary_settings(updates={PREFECT_LOCAL_STORAGE_PATH: root / "prefect-storage"}):
            yield root
    finally:
        if old is None:
            os.environ.pop("REACT3D_CACHE", None)
        else:
            os.environ["REACT3D_CACHE"] = old
        shutil.rmtree(root, ignore_errors=True)


def ensure_scene(entry: dict[str, Any]) -> Path:
    """The entry's scene folder, generated first when the set names a synthetic scene not yet there."""
    scene_dir = Path(entry["scene_dir"])
    if "source" in entry and not (scene_dir / "scans").is_dir():
        from react3d_core.synthetic import generate_scene

        generate_scene(scene_dir, source=entry["source"], seed=entry["seed"], n_frames=entry["n_frames"], kind=entry.get("kind"),
                       **entry.get("synth", {}))
    return scene_dir


def run_one(entry: dict[str, Any], result_dir: str, config: dict[str, Any], cold: str | None = None,
            miss_causes: bool = False) -> dict[str, Any]:
    """Child-process body: generate if missing, convert (timed), return timings and peak RSS.

    ``cold``: a scratch folder; the conversion then starts from an empty cache (see :func:`cold_cache`).
    ``miss_causes``: also attribute each missed / mis-jointed GT part to a stage (flows.bench.miss_causes), after
    the timings and peak memory are taken.
    """
    scene_dir = ensure_scene(entry)
    from flows.convert_scene import convert_scene

    rss0 = _peak_rss_mb()
    with cold_cache(cold) if cold else nullcontext():
        t0 = time.perf_counter()
        manifest = convert_scene(str(scene_dir), result_dir, config)
        wall = time.perf_counter() - t0
        out = {"manifest": str(manifest), "wall_s": wall, "peak_rss_mb": _peak_rss_mb(), "rss_before_mb": rss0}
        if miss_causes:
            try:
                from .miss_causes import trace_scene

                out["miss_causes"] = trace_scene(str(scene_dir), str(manifest), config)
            except Exception as exc:  # noqa: BLE001 - a failed breakdown must not fail the scene's scores
                out["miss_causes"] = {"error": f"{exc.__class__.__name__}: {exc}"}
    return out


def _stopping_server(fn: Callable[..., Any], *args: Any) -> Any:
    """Child body: ``fn(*args)``, then stop Prefect's temporary server. The pool terminates its worker,
    so the server's atexit hook never runs: every benchmarked scene left a uvicorn process behind
    (~200 MB and some CPU each; 98 of them slowed a held-out run two-fold)."""
    try:
        return fn(*args)
    finally:
        from prefect.server.api.server import SubprocessASGIServer

        SubprocessASGIServer().stop()


def run_isolated(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` in a fresh spawned process (its own peak RSS, no state shared with earlier scenes)."""
    ctx = mp.get_context("spawn")
    with ctx.Pool(1, maxtasksperchild=1) as pool:
        return pool.apply(_stopping_server, (fn, *args))


def _gt_dir(scene_dir: Path) -> Path | None:
    for c in (scene_dir / "articulate3d", scene_dir.parent / "articulate3d"):
        if any(c.glob("*_parts.json")):
            return c
    return None


def run_bench(entries: list[dict[str, Any]], out_dir: Path, config: dict[str, Any], cold: bool = False,
              miss_causes: bool = False) -> dict[str, Any]:
    """Convert and evaluate every entry; failed scenes are reported in ``failed`` and skipped.

    ``cold``: each scene converts with an empty cache (a fresh ``out_dir/.cold-cache-*``, removed after).
    ``miss_causes``: each scene gets ``miss_causes`` (counts per cause and one row per traced GT part)
    and the result a pooled ``miss_causes`` (every cause key present; docs/evaluation.md)."""
    from react3d_core.config.metrics import EvaluationConfig
    from react3d_core.data.parts import InteractiveScene
    from react3d_core.ground_truth.articulate3d import read_articulate3d
    from react3d_core.metrics import evaluate_scene, to_json_dict
    from react3d_core.metrics.miss_causes import pool_counts

    scenes, failed, causes = [], [], []
    for e in entries:
        res_dir = out_dir / "results" / e["name"]
        try:
            if "source" not in e and not Path(e["scene_dir"]).is_dir():
                raise InputError(e["scene_dir"], "scene folder not found")
            r = run_isolated(run_one, e, str(res_dir), config, str(out_dir) if cold else None, miss_causes)
            pred = InteractiveScene.load(r["manifest"])
            gt_dir = _gt_dir(Path(e["scene_dir"]))
            if gt_dir is None:
                raise InputError(e["scene_dir"], "no articulate3d/ ground truth to evaluate against")
            sm = evaluate_scene(pred, Path(r["manifest"]).parent, read_articulate3d(gt_dir), EvaluationConfig(**config.get("evaluation", {})))
            sm.scene = e["name"]
            sm.wall_s, sm.peak_rss_mb = r["wall_s"], r["peak_rss_mb"]
            sm.frames = e.get("n_frames")
            scenes.append(sm)
            causes.append(r.get("miss_causes"))
        except Exception as exc:  # noqa: BLE001 - one failed scene must not stop the benchmark
            failed.append({"scene": e["name"], "error": f"{exc.__class__.__name__}: {exc}"})
    result = to_json_dict(scenes)
    if miss_causes:
        for row, mc in zip(result["scenes"], causes):
            row["miss_causes"] = mc
        result["miss_causes"] = pool_counts([mc for mc in causes if mc and "counts" in mc])
    result["failed"] = failed
    result["config"] = config
    return result


def print_table(result: dict[str, Any]) -> None:
    from flows.commands._console import wide_console
    from rich.table import Table

    def f(v: Any, pct: bool = False) -> str:
        return "–" if v is None else (f"{100 * v:.1f}" if pct else f"{v:.3f}" if isinstance(v, float) else str(v))

    t = Table(title="react3d bench")
    for c in ("scene", "GT", "pred", "frames", "faces", "wall s", "peak MB", "F1@.25", "F1@.5", "acc %", "MD m", "OE °", "+MOD %"):
        t.add_column(c, justify="right" if c != "scene" else "left")
    rows = [(s["scene"], s) for s in result["scenes"]] + [("ALL (pooled)", {"n_gt": sum(s["n_gt"] for s in result["scenes"]),
            "n_pred": sum(s["n_pred"] for s in result["scenes"]), **result["aggregate"]})]
    for name, s in rows:
        a, b = s.get("0.25", {}), s.get("0.5", {})
        t.add_row(name, f(s.get("n_gt")), f(s.get("n_pred")), f(s.get("frames")), f(s.get("faces")), f(s.get("wall_s")),
                  f(s.get("peak_rss_mb")), f(a.get("f1")), f(b.get("f1")), f(a.get("joint_acc"), True), f(a.get("md")),
                  f(a.get("oe")), f(a.get("mod"), True))
    console = wide_console()
    console.print(t)
    mc = result.get("miss_causes")
    if mc:
        for kind, title in (("miss", "missed or IoU < 0.5"), ("joint", "joint errors")):
            top = sorted(((n, k) for k, n in mc[kind].items() if n), reverse=True)
            console.print(f"causes, {title}: " + (", ".join(f"{k} {n}" for n, k in top) if top else "none"))
    for fl in result.get("failed", []):
        console.print(f"[red]failed[/red] {fl['scene']}: {fl['error']}")
