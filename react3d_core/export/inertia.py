"""Inertials from collision volume and a density: mass, centre of mass, principal moments and axes."""

from __future__ import annotations

import warnings

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from .collision import ConvexPiece


def rpy_of(R: np.ndarray) -> np.ndarray:
    """URDF rpy (extrinsic XYZ roll, pitch, yaw) of rotation matrix ``R``.

    Axis-aligned frames (principal axes of symmetric parts, boxes standing on end) often have a pitch of
    +-90 degrees (gimbal lock): SciPy then sets the yaw to 0 and the roll takes the rest, which still gives
    ``R`` exactly, so its warning about it is silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return Rotation.from_matrix(R).as_euler("xyz")


@dataclass
class Inertial:
    """Mass (kg), centre of mass (world, m), principal moments (kg m^2) and axes (columns, det +1)."""

    mass: float
    com: np.ndarray
    moments: np.ndarray
    axes: np.ndarray

    def tensor(self) -> np.ndarray:
        """Full 3x3 inertia tensor about the COM in world axes."""
        return self.axes @ np.diag(self.moments) @ self.axes.T

    def rpy(self) -> np.ndarray:
        """URDF rpy (extrinsic XYZ) of the principal frame."""
        return rpy_of(self.axes)

    def quat_wxyz(self) -> np.ndarray:
        x, y, z, w = Rotation.from_matrix(self.axes).as_quat()
        return np.array([w, x, y, z])

    def about_joint(self, joint_type: str, axis: np.ndarray, anchor: np.ndarray) -> float:
        """What a joint moves: the mass along a slide, or the moment about a hinge's line (the inertia
        about the parallel line through the centre of mass plus ``m d^2``)."""
        if joint_type != "revolute":
            return float(self.mass)
        a = np.asarray(axis, float) / np.linalg.norm(axis)
        r = np.asarray(self.com, float) - np.asarray(anchor, float)
        d = r - np.dot(r, a) * a
        return float(a @ self.tensor() @ a + self.mass * np.dot(d, d))


def combine(masses: np.ndarray, coms: np.ndarray, tensors: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Sum rigid pieces: total mass, COM, tensor about the COM (parallel-axis theorem)."""
    m = float(np.sum(masses))
    c = (masses[:, None] * coms).sum(0) / m
    d = coms - c
    shift = masses[:, None, None] * (np.einsum("ij,ij->i", d, d)[:, None, None] * np.eye(3) - np.einsum("ij,ik->ijk", d, d))
    return m, c, (tensors + shift).sum(0)


def principal(tensor: np.ndarray, floor: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (clamped >= floor, triangle inequality enforced) and right-handed axes."""
    w, V = np.linalg.eigh(0.5 * (tensor + tensor.T))
    if np.linalg.det(V) < 0:
        V[:, 2] *= -1
    w = np.maximum(w, floor)
    for i in range(3):  # numerical guard: I_i <= I_j + I_k
        j, k = (i + 1) % 3, (i + 2) % 3
        w[i] = min(w[i], w[j] + w[k])
    return w, V


def inertial_from_pieces(pieces: list[ConvexPiece], density: float, min_mass: float) -> Inertial:
    """Inertial of a body made of convex pieces of uniform ``density``; light bodies are scaled to ``min_mass``."""
    if not pieces:
        raise ValueError("a body needs collision pieces for its inertial")
    ms, cs, Is = [], [], []
    for p in pieces:
        tm = trimesh.Trimesh(p.vertices, p.faces, process=False)
        tm.density = density
        with np.errstate(invalid="ignore", divide="ignore"):  # a flat piece: no volume, skipped below
            props = tm.mass_properties
            vol = abs(float(props["volume"]))
        if vol <= 0:
            continue
        ms.append(vol * density)
        cs.append(np.asarray(props["center_mass"], float))
        Is.append(np.asarray(props["inertia"], float) * np.sign(props["volume"]))
    if not ms:
        raise ValueError("collision pieces have no volume")
    m, c, I = combine(np.asarray(ms), np.asarray(cs), np.asarray(Is))
    if m < min_mass:
        I = I * (min_mass / m)
        m = min_mass
    w, V = principal(I)
    return Inertial(m, c, w, V)
