"""Physics check: drive every exported joint in the simulators and probe cavities and fronts."""

from pydantic import Field, field_validator

from ._base import StageConfig

ENGINES = ("mujoco", "pybullet", "sapien")
"""Simulators the check knows (each optional: skipped with a reason when its package is missing)."""


class PhysicsConfig(StageConfig):
    """How the exported scene is driven and judged (docs/physics.md has the definitions)."""

    enabled: bool = Field(True, description="Run the physics check at the end of convert (a failed check never fails the conversion).")
    engines: tuple[str, ...] = Field(
        ("mujoco",),
        description="Engines convert runs, one after another in one process. MuJoCo is the cheap default; "
        "`react3d check` runs all three unless told otherwise.",
    )
    probes: bool = Field(True, description="Drop a probe into each open cavity and push one against each closed front.")
    reach_fraction: float = Field(0.9, gt=0, le=1, description="A joint passes if it gets this fraction of its upper limit.")
    max_penetration_m: float = Field(0.01, gt=0, description="Deepest allowed contact penetration of a driven part or a probe (m).")
    return_fraction: float = Field(0.1, gt=0, le=1, description="After closing, the joint must be within this fraction of its range of 0.")
    drive_hz: float = Field(5.0, gt=0, description="Natural frequency of the PD drive: kp = I w^2, kd = 2 I w (critically damped), I the joint's inertia.")
    max_force: float = Field(100.0, gt=0, description="Drive force limit (N for a slide, N m for a hinge).")
    revolute_speed: float = Field(1.0, gt=0, description="Speed of the target trajectory of a hinge (rad/s).")
    prismatic_speed: float = Field(0.5, gt=0, description="Speed of the target trajectory of a slide (m/s).")
    min_move_s: float = Field(0.5, gt=0, description="Shortest opening (and closing) trajectory (s).")
    max_move_s: float = Field(2.5, gt=0, description="Longest opening (and closing) trajectory (s).")
    hold_s: float = Field(0.4, ge=0, description="Hold at the upper limit and again at 0 after each trajectory (s).")
    rest_s: float = Field(0.5, gt=0, description="Settling time with every joint held at 0, before any joint is driven (s).")
    drift_rad: float = Field(0.02, gt=0, description="A hinge that moves more than this while held at rest drifts (rad).")
    drift_m: float = Field(0.005, gt=0, description="A slide that moves more than this while held at rest drifts (m).")
    max_speed_rad: float = Field(20.0, gt=0, description="Joint speed above this is a blow-up (rad/s).")
    max_speed_m: float = Field(5.0, gt=0, description="Joint speed above this is a blow-up (m/s).")
    timestep: float = Field(1 / 240, gt=0, le=0.02, description="PyBullet and SAPIEN time step (s); MuJoCo uses the MJCF's own.")
    pybullet_contact_breaking_m: float = Field(
        0.002, gt=0, description="PyBullet's contactBreakingThreshold (m), below the export's collider clearance: its default "
                                 "(0.02) keeps contact points of colliders a few mm apart, whose stale normals jam a part sliding past them.")
    contact_hz: float = Field(100.0, gt=0, description="Contacts of a driven part are read at this rate (every step if the step is longer); a probe's every step.")
    probe_radius_m: float = Field(0.03, gt=0, description="Probe sphere radius (shrunk to 15 % of a small cavity's smallest side).")
    probe_mass_kg: float = Field(0.1, gt=0, description="Probe sphere mass.")
    probe_speed: float = Field(0.5, gt=0, description="Speed at which the front probe is pushed at a closed front (m/s), a gripper's approach.")
    cavity_probe_s: float = Field(1.0, gt=0, description="Time the cavity probe is left to fall and settle (s).")
    cavity_drop_m: float = Field(0.1, gt=0, description="The cavity probe falls from at most this height above the cavity's floor (m), as an object is put "
                                                       "into a cupboard (the cavity's centre is still checked for clearance): dropped from a tall "
                                                       "cavity's centre, a small probe hits at 2-3 m/s and MuJoCo's soft contact lets it sink through a 1.5 cm board.")
    cull_contacts: bool = Field(
        True, description="While one joint is driven or one probe flies, links held at 0 that neither can come near (further than "
                          "cull_margin_m from the box swept by the driven part, or from the probe's path) sit out of contacts; an "
                          "episode that leaves what was assumed (the joint past its range by more than cull_overshoot, the probe "
                          "out of its path, a held link touched) is run again with every collider on. Same results, a fraction of "
                          "the narrow phase in a large scene (MuJoCo, SAPIEN).")
    cull_margin_m: float = Field(0.05, gt=0, description="Links within this distance (m) of an episode's region keep their contacts (cull_contacts).")
    cull_overshoot: float = Field(0.1, ge=0, description="A driven joint is assumed to stay within 0..goal widened by this fraction of the range at each end (cull_contacts).")
    front_probe_s: float = Field(0.4, gt=0, description="Time the front probe flies and bounces (s); longer for a deep front, so that an unhindered probe ends 5 cm past its back face.")

    @field_validator("engines")
    @classmethod
    def _known(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        bad = [e for e in v if e not in ENGINES]
        if bad:
            raise ValueError(f"unknown engine(s) {bad}: choose from {', '.join(ENGINES)}")
        return tuple(dict.fromkeys(v))
