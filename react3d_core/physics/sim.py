"""The few things the check asks of a simulator, so that the episodes (``drive.py``) are written once.

Each engine module (``mujoco_sim``, ``pybullet_sim``, ``sapien_sim``) loads an exported file as a user
would and implements :class:`Sim`. A joint is driven by a PD law on its position,
``f = kp (q* - q) + kd (qd* - qd)``, clipped to ``+-fmax``: applied as a generalized force each step in
MuJoCo and PyBullet, as the PhysX joint drive (the same law, integrated implicitly) in SAPIEN.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from .targets import JointPose

PROBE = "probe"
"""Body name of the probe sphere in contacts."""

TOUCH = 1e-3
"""Contact points closer than this (m) count as touching: PhysX and Bullet resolve a contact before the
bodies meet, so a resting or bouncing contact may keep a small positive separation."""


@dataclass(frozen=True)
class SimJoint(JointPose):
    link: str
    lower: float
    upper: float
    inertia: float  # about (hinge) or along (slide) the axis at q = 0: kg m^2 or kg


@dataclass(frozen=True)
class Contact:
    """One contact point between bodies ``a`` and ``b`` (link names; ``PROBE`` for the probe)."""

    a: str
    b: str
    dist: float  # signed: < 0 penetrating
    geom_a: str | None = None
    geom_b: str | None = None


def effective_inertia(joint_type: str, axis: np.ndarray, anchor: np.ndarray, mass: float, com: np.ndarray,
                      inertia_world: np.ndarray) -> float:
    """What the drive moves: the mass along a slide, or the moment about a hinge's line (the body's inertia
    about the parallel line through its centre of mass plus ``m d^2``)."""
    if joint_type == "prismatic":
        return float(mass)
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    r = np.asarray(com, float) - np.asarray(anchor, float)
    d = r - np.dot(r, a) * a
    return float(a @ np.asarray(inertia_world, float) @ a + mass * np.dot(d, d))


class Sim(ABC):
    """One loaded scene in one engine. Joint vectors follow ``joints``' order."""

    engine: str
    version: str
    dt: float
    joints: list[SimJoint]
    moving: frozenset[str]  # links moved by some joint (their contacts count)
    settings: dict

    @abstractmethod
    def set_gains(self, kp: np.ndarray, kd: np.ndarray, fmax: float) -> None: ...

    @abstractmethod
    def reset(self, q: np.ndarray) -> None:
        """Every joint at ``q`` at rest; the probe (if any) removed."""

    @abstractmethod
    def step(self, q_target: np.ndarray, qd_target: np.ndarray) -> None:
        """One time step with the drives pulling toward the targets."""

    @abstractmethod
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) of every joint."""

    @abstractmethod
    def contacts(self, only: frozenset[str] | None = None) -> list[Contact]:
        """Contact points now with distance <= ``TOUCH``; ``only``: those touching one of these bodies."""

    @abstractmethod
    def add_probe(self, pos: np.ndarray, vel: np.ndarray, radius: float, mass: float, gravity: bool) -> None: ...

    @abstractmethod
    def probe(self) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity of the probe's centre."""

    link_parent: dict[str, str | None] = {}
    """Parent link of every moving link (None at the root); read by :meth:`carried`."""

    def link_boxes(self) -> dict[str, np.ndarray]:  # noqa: B027 - optional
        """World boxes (2x3: lower, upper corner) of each moving link's colliders in the current state.
        Empty when the engine cannot take links out of contacts (:meth:`collide_only`): every episode then
        runs with every collider on."""
        return {}

    def collide_only(self, links: frozenset[str] | None) -> None:  # noqa: B027 - optional
        """Moving links outside ``links`` take part in no contact (the links that never move and the probe
        keep theirs); ``None``: every collider as loaded."""

    def carried(self, i: int) -> frozenset[str]:
        """The links joint ``i`` moves: its child link and every moving link below it."""
        top = self.joints[i].link
        out = set()
        for name in self.link_parent:
            n: str | None = name
            while n is not None:
                if n == top:
                    out.add(name)
                    break
                n = self.link_parent.get(n)
        return frozenset(out | {top})

    def close(self) -> None:  # noqa: B027 - optional
        """Release the engine's resources."""
