"""What the physics check found: per engine, the scene at rest, each joint driven, each probe.

Lengths in metres, angles in radians, times in seconds. A penetration is the depth of the deepest
contact (the engine's negative contact distance / separation, reported as a positive number).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

Vec3 = tuple[float, float, float]


class Touch(BaseModel):
    """Another body a moving body (or probe) was in contact with, and how deep at worst."""

    model_config = ConfigDict(frozen=True)

    body: str
    depth: float = Field(description="Deepest penetration against it (m, 0 = touching).")
    geom: str | None = Field(None, description="The other geom of the deepest contact, where the engine names geoms (MuJoCo).")


class Pair(BaseModel):
    """Two bodies in contact at rest."""

    model_config = ConfigDict(frozen=True)

    a: str
    b: str
    depth: float
    points: int
    moving: bool = Field(description="At least one of the two bodies is moved by a joint.")


class RestCheck(BaseModel):
    """Every joint held at 0: contacts after the first step, and drift while settling."""

    contacts: int = Field(description="Penetrating contact points after one step, all pairs.")
    moving_contacts: int = Field(description="Of those, points on a body moved by a joint.")
    deepest: float = Field(description="Deepest penetration among pairs with a moving body (m).")
    deepest_static: float = Field(0.0, description="Deepest penetration between bodies that never move (m): harmless to motion.")
    pairs: list[Pair] = Field(default_factory=list, description="Deepest pairs first (at most 30).")
    drift: dict[str, float] = Field(default_factory=dict, description="joint -> largest |q| while held at 0.")


class JointCheck(BaseModel):
    """One joint driven alone to its upper limit and back."""

    joint: str
    link: str
    object_id: str | None = None
    joint_type: Literal["revolute", "prismatic"]
    lower: float
    upper: float
    reached: float = Field(description="Largest q / upper while opening and holding.")
    time_to_reach: float | None = Field(None, description="Seconds from the start until q >= reach_fraction x upper (None: never).")
    returned: float = Field(description="|q| / upper after closing and holding (0 = back shut).")
    penetration: float = Field(description="Deepest penetration of the driven link against any other body (m), at rest included.")
    touched: list[Touch] = Field(default_factory=list, description="Bodies the driven link touched, deepest first.")
    rest_drift: float = 0.0
    max_speed: float = 0.0
    unstable: str | None = Field(None, description="'nan', 'blow-up' or 'drift' (with when / how much), None if stable.")
    passed: bool
    causes: list[str] = Field(default_factory=list)


class ProbeCheck(BaseModel):
    """A sphere dropped into an open cavity (must be free) or pushed against a closed front (must be blocked)."""

    kind: Literal["cavity", "front"]
    object_id: str
    joint: str
    radius: float
    start: Vec3
    end: Vec3
    spawn_depth: float = Field(0.0, description="Penetration of the probe right after it was placed (m).")
    penetration: float = Field(0.0, description="Deepest penetration of the probe during the run (m).")
    advance: float | None = Field(None, description="Front probe: deepest reach of its leading point past the front's back face (m; <= 0: never got through).")
    touched: list[Touch] = Field(default_factory=list, description="Bodies in order of first contact.")
    passed: bool
    cause: str | None = None


class EngineCheck(BaseModel):
    engine: str
    version: str | None = None
    status: Literal["ok", "skipped", "error"]
    reason: str | None = None
    file: str | None = Field(None, description="The exported file the engine loaded, relative to the output folder.")
    settings: dict[str, Any] = Field(default_factory=dict)
    seconds: float = Field(0.0, description="Wall-clock seconds: load and every episode.")
    cpu_seconds: float = Field(0.0, description="CPU seconds of this process meanwhile (the cost on a busy machine).")
    rest: RestCheck | None = None
    joints: list[JointCheck] = Field(default_factory=list)
    probes: list[ProbeCheck] = Field(default_factory=list)

    def summary(self, reach: float = 0.9) -> dict[str, Any]:
        """The numbers of the table's summary line (and of the manifest's ``physics`` key); ``reach``: the
        fraction of the upper limit counted as reached."""
        out: dict[str, Any] = {"status": self.status, "seconds": round(self.seconds, 2), "cpu_seconds": round(self.cpu_seconds, 2)}
        if self.status != "ok":
            out["reason"] = self.reason
            return out
        cav = [p for p in self.probes if p.kind == "cavity"]
        fr = [p for p in self.probes if p.kind == "front"]
        out.update({
            "joints": len(self.joints),
            "passed": sum(j.passed for j in self.joints),
            "reached": sum(j.reached >= reach for j in self.joints),
            "max_penetration": max((j.penetration for j in self.joints), default=0.0),
            "unstable": sum(j.unstable is not None for j in self.joints),
            "rest_contacts": self.rest.moving_contacts if self.rest else None,
            "rest_deepest": self.rest.deepest if self.rest else None,
            "cavities_free": sum(p.passed for p in cav), "cavities": len(cav),
            "fronts_blocked": sum(p.passed for p in fr), "fronts": len(fr),
        })
        return out

    @property
    def passed(self) -> bool:
        return self.status == "ok" and all(j.passed for j in self.joints) and all(p.passed for p in self.probes)


class PhysicsCheck(BaseModel):
    """The whole check of one exported scene (``physics_check.json``)."""

    scene_id: str
    engines: list[EngineCheck]
    thresholds: dict[str, float] = Field(default_factory=dict)
    seconds: float = 0.0
    created: str = ""

    @property
    def ran(self) -> list[EngineCheck]:
        return [e for e in self.engines if e.status != "skipped"]

    @property
    def passed(self) -> bool:
        """Every engine that was asked and is installed ran, and every joint and probe in it passed."""
        return bool(self.ran) and all(e.passed for e in self.ran)

    def summary(self) -> dict[str, Any]:
        """Small enough for ``scene.json``: per engine its summary line, and the overall verdict."""
        return {"passed": self.passed, "engines": {e.engine: e.summary(self.thresholds.get("reach_fraction", 0.9)) for e in self.engines},
                "thresholds": self.thresholds, "seconds": round(self.seconds, 2), "created": self.created}
