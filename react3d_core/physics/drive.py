"""The check's episodes, written once over :class:`~.sim.Sim`: rest, each joint driven alone, probes.

Drive: every joint has the PD law of ``sim.py`` with ``kp = I w^2``, ``kd = 2 I w`` (critically damped,
``w = 2 pi drive_hz``, ``I`` the joint's inertia at q = 0), force limit ``max_force``. Joints not being
driven are held at 0 by the same law. The driven joint's target follows a smoothstep from 0 to its goal
(the upper limit; the lower one for a joint that only opens below 0) in ``T = clip(|goal| / speed,
min_move_s, max_move_s)``, holds ``hold_s``, returns to 0 in ``T`` and holds ``hold_s`` again; the target
velocity is the smoothstep's derivative.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..config.physics import PhysicsConfig
from . import reach
from .result import JointCheck, Pair, ProbeCheck, RestCheck, Touch
from .sim import PROBE, Contact, Sim, SimJoint
from .targets import Front, advance, cavity_box, cavity_probe, fell_enough, front_probe

SPAWN_TOL = 1e-3
"""A probe placed deeper than this (m) into something was placed inside a collider: the space is not free."""


def gains(joints: list[SimJoint], cfg: PhysicsConfig) -> tuple[np.ndarray, np.ndarray]:
    w = 2 * math.pi * cfg.drive_hz
    inertia = np.array([max(j.inertia, 1e-4) for j in joints])
    return inertia * w * w, 2 * inertia * w


def smoothstep(x: float) -> tuple[float, float]:
    """s(x) = 3x^2 - 2x^3 on [0, 1] and its derivative."""
    x = min(max(x, 0.0), 1.0)
    return 3 * x * x - 2 * x ** 3, 6 * x * (1 - x)


def goal_of(j: SimJoint) -> float:
    return j.upper if j.upper > 0 else j.lower


def move_time(j: SimJoint, cfg: PhysicsConfig) -> float:
    speed = cfg.revolute_speed if j.joint_type == "revolute" else cfg.prismatic_speed
    return float(np.clip(abs(goal_of(j)) / speed, cfg.min_move_s, cfg.max_move_s))


def target(t: float, goal: float, T: float, hold: float) -> tuple[float, float]:
    """Position and velocity of the driven joint's target at time ``t`` (module doc)."""
    if t < T:
        s, ds = smoothstep(t / T)
        return goal * s, goal * ds / T
    if t < T + hold:
        return goal, 0.0
    if t < 2 * T + hold:
        s, ds = smoothstep((t - T - hold) / T)
        return goal * (1 - s), -goal * ds / T
    return 0.0, 0.0


def speed_limits(joints: list[SimJoint], cfg: PhysicsConfig) -> np.ndarray:
    return np.array([cfg.max_speed_rad if j.joint_type == "revolute" else cfg.max_speed_m for j in joints])


def instability(q: np.ndarray, qd: np.ndarray, vmax: np.ndarray, joints: list[SimJoint], t: float,
                watch: list[int] | None = None) -> str | None:
    """'nan' when any joint's state is not finite (the whole simulation is lost), 'blow-up' when a watched
    joint (default: all) moves faster than its limit; None otherwise."""
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
        return f"nan at {t:.2f} s"
    idx = list(range(len(joints))) if watch is None else watch
    ratio = np.abs(qd[idx]) / vmax[idx]
    if ratio.size and ratio.max() > 1:
        k = idx[int(np.argmax(ratio))]
        return f"blow-up at {t:.2f} s ({joints[k].name} at {abs(qd[k]):.1f}/s)"
    return None


@dataclass
class ContactLog:
    """Contacts of the watched bodies with any other body: deepest per body, in order of first contact."""

    watch: frozenset[str]
    order: list[str] = field(default_factory=list)
    depth: dict[str, float] = field(default_factory=dict)
    geom: dict[str, str | None] = field(default_factory=dict)

    def add(self, contacts: list[Contact]) -> None:
        for c in contacts:
            if c.a in self.watch and c.b not in self.watch:
                other, g = c.b, c.geom_b
            elif c.b in self.watch and c.a not in self.watch:
                other, g = c.a, c.geom_a
            else:
                continue
            d = max(0.0, -c.dist)
            if other not in self.depth:
                self.order.append(other)
                self.depth[other], self.geom[other] = d, g
            elif d > self.depth[other]:
                self.depth[other], self.geom[other] = d, g

    @property
    def deepest(self) -> float:
        return max(self.depth.values(), default=0.0)

    def touches(self, by_depth: bool = True) -> list[Touch]:
        names = sorted(self.order, key=lambda n: -self.depth[n]) if by_depth else self.order
        return [Touch(body=n, depth=self.depth[n], geom=self.geom[n]) for n in names]


def _steps(seconds: float, dt: float) -> int:
    return max(1, int(math.ceil(seconds / dt - 1e-9)))


def _every(cfg: PhysicsConfig, dt: float) -> int:
    return max(1, int(round(1.0 / (cfg.contact_hz * dt))))


@dataclass
class Culling:
    """Contacts of each episode limited to the links it can reach (``reach.py``): the moving links' boxes
    at q = 0, what each joint carries, and how many episodes ran culled or had to be run again in full."""

    boxes: dict[str, np.ndarray]
    carried: list[frozenset[str]]
    moving: frozenset[str]
    margin: float
    overshoot: float
    culled: int = 0
    rerun: int = 0
    reruns: list[str] = field(default_factory=list)

    def swept(self, sim: Sim, i: int, q0: float, q1: float) -> np.ndarray | None:
        """Box swept by what joint ``i`` carries from ``q0`` to ``q1`` (None: it carries no collider)."""
        j = sim.joints[i]
        return reach.merge(reach.swept(self.boxes[n], j, q0, q1) for n in self.carried[i] if n in self.boxes)

    def links(self, i: int, region: np.ndarray | None) -> frozenset[str]:
        """What joint ``i`` carries and every moving link within ``margin`` of ``region``."""
        if region is None:
            return self.carried[i]
        return reach.needed(self.boxes, region, self.margin, self.carried[i])

    def neighbours_touched(self, i: int, touched: list[Touch]) -> list[str]:
        """Moving links, other than what joint ``i`` carries, among ``touched``: a held link that was
        touched may be pushed into one that sat out."""
        return [t.body for t in touched if t.body in self.moving and t.body not in self.carried[i]]

    def settings(self) -> dict:
        return {"margin_m": self.margin, "overshoot": self.overshoot, "episodes_culled": self.culled,
                "episodes_rerun_in_full": self.rerun, "reruns": self.reruns}


def culling(sim: Sim, cfg: PhysicsConfig) -> Culling | None:
    """The culling of ``sim`` (None when switched off or when the engine cannot do it)."""
    if not cfg.cull_contacts:
        return None
    sim.reset(np.zeros(len(sim.joints)))
    boxes = sim.link_boxes()
    if not boxes:
        return None
    return Culling(boxes, [sim.carried(i) for i in range(len(sim.joints))], sim.moving, cfg.cull_margin_m, cfg.cull_overshoot)


def _culled(sim: Sim, cull: Culling | None, links: frozenset[str] | None, run: Callable[[], tuple],
            fine: Callable[[tuple], str | None], what: str) -> tuple:
    """``run()`` with only ``links`` colliding; run again with every collider on when ``fine(result)``
    names something the culled run did not assume."""
    if cull is None or links is None:
        return run()
    sim.collide_only(links)
    try:
        out = run()
    finally:
        sim.collide_only(None)
    why = fine(out)
    if why is None:
        cull.culled += 1
        return out
    cull.rerun += 1
    cull.reruns.append(f"{what}: {why}")
    return run()


def rest(sim: Sim, cfg: PhysicsConfig) -> tuple[RestCheck, dict[str, str]]:
    """Every joint held at 0 for ``rest_s``: contacts after the first step, the largest |q| of each joint.
    Returns the result and, per joint, a drift or instability found here."""
    n = len(sim.joints)
    zeros = np.zeros(n)
    sim.reset(zeros)
    vmax = speed_limits(sim.joints, cfg)
    drift = np.zeros(n)
    first: list[Contact] = []
    bad: dict[str, str] = {}
    for k in range(_steps(cfg.rest_s, sim.dt)):
        sim.step(zeros, zeros)
        if k == 0:
            first = sim.contacts()
        q, qd = sim.state()
        t = (k + 1) * sim.dt
        if instability(q, qd, vmax, sim.joints, t, watch=[]):  # not finite: every joint is lost
            bad.update({j.name: f"nan at {t:.2f} s while held at 0" for j in sim.joints if j.name not in bad})
            break
        for i, j in enumerate(sim.joints):
            if j.name not in bad and abs(qd[i]) > vmax[i]:
                bad[j.name] = f"blow-up at {t:.2f} s while held at 0 ({abs(qd[i]):.1f}/s)"
        drift = np.maximum(drift, np.abs(q))
    pairs: dict[tuple[str, str], list[float]] = {}
    for c in first:
        key = tuple(sorted((c.a, c.b)))
        pairs.setdefault(key, []).append(max(0.0, -c.dist))  # type: ignore[arg-type]
    rows = [Pair(a=a, b=b, depth=max(d), points=len(d), moving=a in sim.moving or b in sim.moving) for (a, b), d in pairs.items()]
    rows.sort(key=lambda p: (-p.depth, p.a, p.b))
    moving = [p for p in rows if p.moving]
    tol = np.array([cfg.drift_rad if j.joint_type == "revolute" else cfg.drift_m for j in sim.joints])
    for j, d, t in zip(sim.joints, drift, tol):
        if j.name not in bad and d > t:
            unit = "rad" if j.joint_type == "revolute" else "m"
            bad[j.name] = f"drift {d:.3f} {unit} while held at 0"
    out = RestCheck(contacts=len(first), moving_contacts=sum(p.points for p in moving),
                    deepest=max((p.depth for p in moving), default=0.0),
                    deepest_static=max((p.depth for p in rows if not p.moving), default=0.0),
                    pairs=rows[:30], drift={j.name: float(d) for j, d in zip(sim.joints, drift)})
    return out, bad


def drive(sim: Sim, i: int, cfg: PhysicsConfig, object_id: str | None, rest_drift: float,
          rest_problem: str | None, cull: Culling | None = None) -> JointCheck:
    """Joint ``i`` driven alone to its goal and back (module doc); the others held at 0. With ``cull``,
    only links within reach of what the joint carries collide (run again in full when the joint left its
    assumed range or touched a held link)."""
    goal = goal_of(sim.joints[i])
    links = lo = hi = None
    if cull is not None and np.isfinite(goal) and goal != 0:
        lo, hi = reach.motion_range(goal, cull.overshoot)
        links = cull.links(i, cull.swept(sim, i, lo, hi))

    def fine(out: tuple) -> str | None:
        res, qmin, qmax = out
        if not (lo <= qmin and qmax <= hi):
            return f"left its assumed range ({qmin:.3f}..{qmax:.3f} outside {lo:.3f}..{hi:.3f})"
        held = cull.neighbours_touched(i, res.touched)
        return f"touched held {', '.join(held)}" if held else None

    return _culled(sim, cull, links, lambda: _drive(sim, i, cfg, object_id, rest_drift, rest_problem), fine,
                   f"drive {sim.joints[i].name}")[0]


def _drive(sim: Sim, i: int, cfg: PhysicsConfig, object_id: str | None, rest_drift: float,
           rest_problem: str | None) -> tuple[JointCheck, float, float]:
    """The episode of :func:`drive`; also the smallest and largest value the joint took."""
    j = sim.joints[i]
    n = len(sim.joints)
    goal = goal_of(j)
    base = dict(joint=j.name, link=j.link, object_id=object_id, joint_type=j.joint_type, lower=j.lower, upper=j.upper,
                rest_drift=rest_drift)
    if not np.isfinite(goal) or goal == 0:
        return JointCheck(**base, reached=0.0, returned=0.0, penetration=0.0, passed=False,
                          causes=["no finite non-zero limit to drive to"]), 0.0, 0.0
    T, hold = move_time(j, cfg), cfg.hold_s
    vmax = speed_limits(sim.joints, cfg)
    sim.reset(np.zeros(n))
    log = ContactLog(frozenset({j.link}))
    every = _every(cfg, sim.dt)
    qt, vt = np.zeros(n), np.zeros(n)
    reached, t_reach, top_speed, unstable = 0.0, None, 0.0, None
    q = np.zeros(n)
    qmin = qmax = 0.0
    for k in range(_steps(2 * T + 2 * hold, sim.dt)):
        t = (k + 1) * sim.dt
        qt[i], vt[i] = target(t, goal, T, hold)
        sim.step(qt, vt)
        if k % every == 0:
            log.add(sim.contacts(log.watch))
        q, qd = sim.state()
        qi = float(q[i])
        qmin, qmax = (min(qmin, qi), max(qmax, qi)) if math.isfinite(qi) else (-math.inf, math.inf)
        unstable = instability(q, qd, vmax, sim.joints, t, watch=[i])
        if unstable:
            break
        top_speed = max(top_speed, abs(float(qd[i])))
        if t <= T + hold + 1e-9:
            frac = float(q[i] / goal)
            reached = max(reached, frac)
            if t_reach is None and frac >= cfg.reach_fraction:
                t_reach = t
    returned = float(abs(q[i] / goal)) if not unstable else 1.0
    unstable = unstable or rest_problem
    causes = []
    touched = log.touches()
    if reached < cfg.reach_fraction:
        near = ", ".join(f"{t.body} {100 * t.depth:.1f} cm" for t in touched[:3])
        causes.append(f"reached {reached:.2f} of its limit" + (f" (touching {near})" if near else ""))
    if log.deepest > cfg.max_penetration_m:
        worst = touched[0]
        causes.append(f"penetrates {worst.body} by {100 * worst.depth:.1f} cm" + (f" ({worst.geom})" if worst.geom else ""))
    if returned > cfg.return_fraction and not unstable:
        causes.append(f"did not close: {returned:.2f} of its limit left")
    if unstable:
        causes.append(unstable)
    return JointCheck(**base, reached=reached, time_to_reach=t_reach, returned=returned, penetration=log.deepest,
                      touched=touched, max_speed=top_speed, unstable=unstable, passed=not causes, causes=causes), qmin, qmax


@dataclass
class ProbePath:
    """The box the probe's centre went through (non-finite: lost)."""

    lo: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    hi: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))
    finite: bool = True

    def add(self, p: np.ndarray) -> None:
        if not np.all(np.isfinite(p)):
            self.finite = False
            return
        self.lo, self.hi = np.minimum(self.lo, p), np.maximum(self.hi, p)

    def within(self, box: np.ndarray) -> bool:
        return self.finite and bool(np.all(self.lo >= box[0]) and np.all(self.hi <= box[1]))


def _probe_region(points: list[np.ndarray], radius: float) -> np.ndarray:
    """Box of the probe's planned centres, grown by its radius."""
    return reach.grow(np.array([np.min(points, axis=0), np.max(points, axis=0)]), radius)


def _probe_fine(cull: Culling, i: int, centres: np.ndarray, radius: float) -> Callable[[tuple], str | None]:
    """Rerun in full when the probe's centre left its planned box (widened by half the margin) or touched
    a held link."""
    def fine(out: tuple) -> str | None:
        res, path = out[0], out[-1]
        if not path.within(reach.grow(centres, cull.margin / 2)):
            return "the probe left its planned path"
        held = cull.neighbours_touched(i, res.touched)
        return f"the probe touched held {', '.join(held)}" if held else None
    return fine


def _probe_loop(sim: Sim, q_hold: np.ndarray, seconds: float, cfg: PhysicsConfig,
                track: Callable[[np.ndarray], None] | None = None, path: ProbePath | None = None) -> tuple[ContactLog, float]:
    """Step with the joints held at ``q_hold``; returns the probe's contacts and how deep it was right
    after being placed (first step)."""
    log = ContactLog(frozenset({PROBE}))
    spawn = 0.0
    zeros = np.zeros_like(q_hold)
    for k in range(_steps(seconds, sim.dt)):
        sim.step(q_hold, zeros)
        cs = sim.contacts(log.watch)  # every step: a bounce lasts one or two
        if k == 0:
            spawn = max((max(0.0, -c.dist) for c in cs), default=0.0)
        log.add(cs)
        if track is not None or path is not None:
            p = sim.probe()[0]
            if track is not None:
                track(p)
            if path is not None:
                path.add(p)
    return log, spawn


def _joint_region(sim: Sim, i: int, cull: Culling) -> tuple[np.ndarray | None, float, float]:
    goal = goal_of(sim.joints[i])
    lo, hi = reach.motion_range(goal, cull.overshoot)
    return cull.swept(sim, i, lo, hi), lo, hi


def cavity(sim: Sim, i: int, f: Front, cfg: PhysicsConfig, cull: Culling | None = None) -> ProbeCheck:
    """:func:`_cavity`; with ``cull``, only links within reach of the joint's swept box and of the probe's
    planned path collide (run again in full when the probe left that path, the joint its range, or the
    probe touched a held link)."""
    links = centres = None
    lo = hi = 0.0
    if cull is not None:
        region, lo, hi = _joint_region(sim, i, cull)
        plan = cavity_probe(f, cfg.probe_radius_m, drop=cfg.cavity_drop_m)
        pts = [plan.center, plan.spawn, *plan.box.corners()]
        if f.moving_cavity:
            pts += [c for q in np.linspace(lo, hi, 9) for c in cavity_box(f).moved(f.articulation, float(q)).corners()]
        centres = _probe_region(pts, 0.0)
        probe = reach.grow(centres, plan.radius)
        links = cull.links(i, probe if region is None else reach.merge([region, probe]))
        inner = _probe_fine(cull, i, centres, plan.radius)

        def fine(out: tuple) -> str | None:
            qmin, qmax = out[1]
            if not (lo <= qmin and qmax <= hi):
                return f"the joint left its assumed range ({qmin:.3f}..{qmax:.3f} outside {lo:.3f}..{hi:.3f})"
            return inner(out)
    else:
        def fine(out: tuple) -> str | None:
            return None

    return _culled(sim, cull, links, lambda: _cavity(sim, i, f, cfg), fine, f"cavity probe {f.object_id}")[0]


def _cavity(sim: Sim, i: int, f: Front, cfg: PhysicsConfig) -> tuple[ProbeCheck, tuple[float, float], ProbePath]:
    """The joint held at its goal; a sphere placed at the cavity's centre for one step (held there), then
    dropped from straight below it, at most ``cavity_drop_m`` above the floor. Free: placed clear of every
    collider both times (<= 1 mm), ends inside the cavity (moved with the joint's final value for a
    drawer) and came down at least half way to the cavity's bottom or rests on nothing but the object's own
    bodies (its carcass floor, the drawer's box). Its deepest penetration is recorded,
    not judged: on impact a soft contact (MuJoCo's) lets it sink a few millimetres into a floor."""
    j = sim.joints[i]
    goal = goal_of(j)
    plan = cavity_probe(f, cfg.probe_radius_m, drop=cfg.cavity_drop_m)
    q = np.zeros(len(sim.joints))
    q[i] = goal
    path = ProbePath()
    qs = [float(goal)]

    def joint(_: np.ndarray) -> None:
        qs.append(float(sim.state()[0][i]))

    sim.reset(q)
    sim.add_probe(plan.center, np.zeros(3), plan.radius, cfg.probe_mass_kg, gravity=False)
    at_center, spawn_c = _probe_loop(sim, q, sim.dt, cfg, joint, path)
    sim.reset(q)
    sim.add_probe(plan.spawn, np.zeros(3), plan.radius, cfg.probe_mass_kg, gravity=True)
    log, spawn = _probe_loop(sim, q, cfg.cavity_probe_s, cfg, joint, path)
    if spawn_c > spawn:
        spawn, log = spawn_c, at_center
    end = sim.probe()[0]
    q_end = float(sim.state()[0][i])
    box = plan.box
    if f.moving_cavity:
        box = cavity_box(f).moved(f.articulation, q_end)
    inside = bool(np.all(np.isfinite(end))) and box.contains(end)
    touched = log.touches(by_depth=False)
    # resting on the cavity's own floor (its carcass, or the drawer's box) is where it should land, however
    # far above the front's lower edge clearance put that floor
    own = {j.link, f"{j.link}_base"}
    fell = inside and (fell_enough(box, plan.spawn, end, plan.radius) or bool(touched and {t.body for t in touched} <= own))
    cause = None
    if spawn > SPAWN_TOL:
        where = max(log.depth, key=log.depth.get) if log.depth else "?"
        cause = f"placed inside {where} ({100 * spawn:.1f} cm deep): the cavity is not free space"
    elif not inside:
        cause = "pushed out of the cavity" + (f" (touching {', '.join(t.body for t in touched[:3])})" if touched else "")
    elif not fell:
        cause = "held up inside the cavity" + (f" by {', '.join(t.body for t in touched[:3])}" if touched else "")
    qr = np.asarray(qs)
    span = (float(qr.min()), float(qr.max())) if np.all(np.isfinite(qr)) else (-math.inf, math.inf)
    return ProbeCheck(kind="cavity", object_id=f.object_id, joint=j.name, radius=plan.radius, start=tuple(plan.spawn),
                      end=tuple(float(x) for x in end), spawn_depth=spawn, penetration=log.deepest, touched=touched,
                      passed=cause is None, cause=cause), span, path


def front(sim: Sim, i: int, f: Front, cfg: PhysicsConfig, cull: Culling | None = None) -> ProbeCheck:
    """:func:`_front`; with ``cull``, only what the joint carries and links within reach of the probe's
    planned path (its straight flight, forward and back) collide (run again in full when the probe left
    that path or touched a held link)."""
    links = None
    fine: Callable[[tuple], str | None] = lambda out: None  # noqa: E731
    if cull is not None:
        plan = front_probe(f, cfg.probe_radius_m, cfg.probe_speed)
        seconds = _front_seconds(f, plan, cfg)
        centres = _probe_region([plan.start - plan.velocity * seconds, plan.start + plan.velocity * seconds], 0.0)
        links = cull.links(i, reach.grow(centres, plan.radius))
        fine = _probe_fine(cull, i, centres, plan.radius)
    return _culled(sim, cull, links, lambda: _front(sim, i, f, cfg), fine, f"front probe {f.object_id}")[0]


def _front_seconds(f: Front, plan, cfg: PhysicsConfig) -> float:  # noqa: ANN001 - a FrontProbe
    """Long enough for an unhindered probe to end 5 cm past the back face, whatever the front's depth."""
    return max(cfg.front_probe_s, (float(np.dot(f.back - plan.start, f.n)) + 0.05) / cfg.probe_speed + 0.1)


def _front(sim: Sim, i: int, f: Front, cfg: PhysicsConfig) -> tuple[ProbeCheck, ProbePath]:
    """Every joint held at 0; a sphere (gravity compensated) pushed at the front's centre, for ``front_probe_s``
    or longer when the front is deep (an unhindered probe ends 5 cm past its back face). Blocked: placed
    clear of every collider, the first body it touches is the front's link, and its leading point never
    gets more than ``max_penetration_m`` past the front's back face (into the cavity)."""
    j = sim.joints[i]
    plan = front_probe(f, cfg.probe_radius_m, cfg.probe_speed)
    q = np.zeros(len(sim.joints))
    sim.reset(q)
    sim.add_probe(plan.start, plan.velocity, plan.radius, cfg.probe_mass_kg, gravity=False)
    deepest = [-np.inf]

    def track(p: np.ndarray) -> None:
        deepest[0] = max(deepest[0], advance(f, p, plan.radius))

    path = ProbePath()
    log, spawn = _probe_loop(sim, q, _front_seconds(f, plan, cfg), cfg, track, path)
    end = sim.probe()[0]
    adv = float(deepest[0]) if np.isfinite(deepest[0]) else None  # None: the probe's state was not finite
    touched = log.touches(by_depth=False)
    cause = None
    if spawn > SPAWN_TOL:
        cause = f"placed inside {max(log.depth, key=log.depth.get)} in front of the front ({100 * spawn:.1f} cm deep)"
    elif adv is None:
        cause = "probe state not finite"
    elif adv > cfg.max_penetration_m:
        first = f"; first touched {touched[0].body}" if touched else "; touched nothing"
        cause = f"passed through the front: {100 * adv:.1f} cm past its back face{first}"
    elif not touched:
        cause = "touched nothing"
    elif touched[0].body != j.link:
        cause = f"hit {touched[0].body} before the front"
    return ProbeCheck(kind="front", object_id=f.object_id, joint=j.name, radius=plan.radius, start=tuple(plan.start),
                      end=tuple(float(x) for x in end), spawn_depth=spawn, penetration=log.deepest, advance=adv,
                      touched=touched, passed=cause is None, cause=cause), path
