"""``check_output(out)``: load a conversion's exported files in each simulator and run the episodes.

Engines run one after another in this process; each is optional (skipped, with the reason, when its
package is missing or the export lacks its format). An engine that raises is recorded as an error with
its message; the check itself only raises for an output folder it cannot read.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from datetime import datetime, timezone
from importlib.util import find_spec
from pathlib import Path

from ..atomic import write_json
from ..config.physics import ENGINES, PhysicsConfig
from ..data.parts import InteractiveScene
from ..errors import InputError
from . import drive
from .result import EngineCheck, JointCheck, PhysicsCheck, ProbeCheck
from .sim import Sim
from .targets import Front, fronts, match_joints

FORMAT = {"mujoco": "mjcf", "pybullet": "urdf", "sapien": "urdf"}
"""The exported file each engine loads."""

INSTALL = {"mujoco": "pip install mujoco (or the sim extra)", "pybullet": "pip install pybullet (or the sim extra)",
           "sapien": "pip install sapien (or the sim extra)"}

ProgressFn = Callable[[str, str], None]
"""``progress(engine, what)``: called before each episode (the CLI prints it)."""

DEFAULT_JSON = "physics_check.json"


def load_output(out: str | Path) -> tuple[Path, InteractiveScene]:
    """The output folder (or its scene.json) and its manifest; a one-line error for anything else."""
    p = Path(out)
    if not p.exists():
        raise InputError(p, "not found: give the --out folder of a `react3d convert` run")
    root = p.parent if p.is_file() else p
    if not (root / "scene.json").is_file():
        raise InputError(root, "is not a react3d conversion output (no scene.json); give the --out folder of a `react3d convert` run")
    scene = InteractiveScene.load(root / "scene.json")
    if not scene.exports:
        raise InputError(root / "scene.json", "the scene was converted without simulator files (export.formats was empty); "
                                              "run `react3d export` on it first")
    return root, scene


def _make(engine: str, path: Path, cfg: PhysicsConfig) -> Sim:
    if engine == "mujoco":
        from .mujoco_sim import MujocoSim

        return MujocoSim(path)
    if engine == "pybullet":
        from .pybullet_sim import PybulletSim

        return PybulletSim(path, cfg.timestep, cfg.pybullet_contact_breaking_m)
    from .sapien_sim import SapienSim

    return SapienSim(path, cfg.timestep)


def run_engine(sim: Sim, targets: list[Front], cfg: PhysicsConfig, progress: ProgressFn | None = None) -> tuple[
        dict, list[JointCheck], list[ProbeCheck], list[str]]:
    """Rest, every joint, every probe in one loaded engine; also the objects no joint of the file moves."""
    say = progress or (lambda e, w: None)
    matched = match_joints(targets, sim.joints)
    kp, kd = drive.gains(sim.joints, cfg)
    sim.set_gains(kp, kd, cfg.max_force)
    say(sim.engine, "rest")
    rest, problems = drive.rest(sim, cfg)
    cull = drive.culling(sim, cfg)
    order = sorted(range(len(sim.joints)), key=lambda i: sim.joints[i].name)
    joints = []
    for i in order:
        j = sim.joints[i]
        say(sim.engine, f"drive {j.name}")
        f = matched.get(j.name)
        joints.append(drive.drive(sim, i, cfg, f.object_id if f else None, rest.drift.get(j.name, 0.0), problems.get(j.name),
                                  cull))
    probes = []
    if cfg.probes:
        for i in order:
            f = matched.get(sim.joints[i].name)
            if f is None:
                continue
            say(sim.engine, f"front probe {f.object_id}")
            probes.append(drive.front(sim, i, f, cfg, cull))
            if f.cavity_depth:
                say(sim.engine, f"cavity probe {f.object_id}")
                probes.append(drive.cavity(sim, i, f, cfg, cull))
    unmatched = sorted({f.object_id for f in targets} - {f.object_id for f in matched.values()})
    if cull is not None:
        sim.settings["contact_culling"] = cull.settings()
    return {"rest": rest}, joints, probes, unmatched


def check_engine(engine: str, root: Path, scene: InteractiveScene, cfg: PhysicsConfig,
                 progress: ProgressFn | None = None) -> EngineCheck:
    if find_spec(engine) is None:  # each engine's package is named after it
        return EngineCheck(engine=engine, status="skipped", reason=f"{engine} is not installed ({INSTALL[engine]})")
    fmt = FORMAT[engine]
    if fmt not in scene.exports:
        return EngineCheck(engine=engine, status="skipped", reason=f"the export has no {fmt.upper()} (export.formats)")
    path = root / scene.exports[fmt]
    if not path.is_file():
        return EngineCheck(engine=engine, status="error", reason=f"{path}: exported file is missing", file=scene.exports[fmt])
    t0, c0 = time.perf_counter(), time.process_time()
    sim: Sim | None = None
    try:
        sim = _make(engine, path, cfg)
        extra, joints, probes, unmatched = run_engine(sim, fronts(scene), cfg, progress)
        out = EngineCheck(engine=engine, version=sim.version, status="ok", file=scene.exports[fmt],
                          settings=dict(sim.settings),
                          rest=extra["rest"], joints=joints, probes=probes,
                          reason=(f"no joint in the file moves {', '.join(unmatched)}" if unmatched else None))
    except Exception as exc:  # noqa: BLE001 - an engine failing is a finding, not a crash of the check
        msg = str(exc).strip().splitlines()[0][:300] if str(exc).strip() else ""
        out = EngineCheck(engine=engine, version=getattr(sim, "version", None), status="error", file=scene.exports[fmt],
                          reason=f"{type(exc).__name__}: {msg}")
    finally:
        if sim is not None:
            sim.close()
    out.seconds, out.cpu_seconds = time.perf_counter() - t0, time.process_time() - c0
    return out


def check_output(out: str | Path, cfg: PhysicsConfig | None = None, engines: tuple[str, ...] | None = None,
                 progress: ProgressFn | None = None) -> PhysicsCheck:
    """Run the check on a conversion output (a folder with scene.json and export/)."""
    cfg = cfg or PhysicsConfig()
    engines = tuple(engines or cfg.engines)
    bad = [e for e in engines if e not in ENGINES]
    if bad:
        raise InputError(None, f"unknown engine(s) {bad}: choose from {', '.join(ENGINES)}")
    root, scene = load_output(out)
    t0 = time.perf_counter()
    results = [check_engine(e, root, scene, cfg, progress) for e in engines]
    thresholds = {"reach_fraction": cfg.reach_fraction, "max_penetration_m": cfg.max_penetration_m,
                  "return_fraction": cfg.return_fraction}
    return PhysicsCheck(scene_id=scene.scene_id, engines=results, thresholds=thresholds,
                        seconds=time.perf_counter() - t0,
                        created=datetime.now(timezone.utc).isoformat(timespec="seconds"))


def write_check(check: PhysicsCheck, path: str | Path) -> Path:
    """The full result as JSON, written to a temporary file and renamed."""
    return write_json(path, check.model_dump(mode="json"))
