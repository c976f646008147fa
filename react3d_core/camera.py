"""Camera math and the conversions between pose conventions, applied only at loader boundaries."""

from __future__ import annotations

import numpy as np

# OpenGL camera (x right, y up, z backward) <-> OpenCV camera (x right, y down, z forward).
GL_TO_CV = np.diag([1.0, -1.0, -1.0, 1.0])

K_SIZE = (1920, 1440)
"""Image size (width, height) the iPhone / ScanNet++ intrinsics are given at (pose_intrinsic_imu.json)."""

REF_WIDTH = 960
"""Pixel sizes in the config (mask areas, erosion, borders, oracle mask noise) are given at this width."""


def scaled_px(px: int | float, width: int) -> int:
    """A pixel length given at ``REF_WIDTH``, for an image ``width`` wide."""
    return int(round(px * width / REF_WIDTH))


def scaled_area_px(px: int | float, width: int) -> float:
    """A pixel area given at ``REF_WIDTH``, for an image ``width`` wide."""
    return px * (width / REF_WIDTH) ** 2


def project(points_world: np.ndarray, K: np.ndarray, w2c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Project world points to pixel coordinates (u right, v down; pixel centres at integers).

    Returns ``(uv (N,2), z (N,))``; z <= 0 means behind the camera.
    """
    p = np.asarray(points_world, float) @ w2c[:3, :3].T + w2c[:3, 3]
    z = p[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = (p[:, :2] / z[:, None]) * [K[0, 0], K[1, 1]] + [K[0, 2], K[1, 2]]
    return uv, z


def unproject(depth: np.ndarray, K: np.ndarray, c2w: np.ndarray) -> np.ndarray:
    """Back-project a depth map (metres, 0 = invalid) to world points, (H, W, 3); invalid -> NaN."""
    h, w = depth.shape
    u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    z = depth.astype(float)
    x = (u - K[0, 2]) / K[0, 0] * z
    y = (v - K[1, 2]) / K[1, 1] * z
    pc = np.stack([x, y, z], -1)
    pw = pc @ c2w[:3, :3].T + c2w[:3, 3]
    pw[z <= 0] = np.nan
    return pw


def ray_directions(K: np.ndarray, c2w: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel world ray origins and unit directions through pixel centres, (H, W, 3) each."""
    u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    d = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    dw = d @ c2w[:3, :3].T
    ow = np.broadcast_to(c2w[:3, 3], dw.shape)
    return ow, dw


def invert(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid 4x4 transform."""
    out = np.eye(4)
    R = T[:3, :3]
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    return out


def opengl_to_opencv_c2w(c2w_gl: np.ndarray) -> np.ndarray:
    """Camera-to-world with OpenGL camera axes -> OpenCV camera axes (negate camera y and z)."""
    return np.asarray(c2w_gl, float) @ GL_TO_CV


def opencv_to_opengl_c2w(c2w_cv: np.ndarray) -> np.ndarray:
    return np.asarray(c2w_cv, float) @ GL_TO_CV


def colmap_to_c2w(qvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    """COLMAP world-to-camera (qw qx qy qz, t) -> 4x4 camera-to-world (OpenCV axes)."""
    R = quat_to_rot(qvec)
    w2c = np.eye(4)
    w2c[:3, :3] = R
    w2c[:3, 3] = np.asarray(tvec, float)
    return invert(w2c)


def c2w_to_colmap(c2w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`colmap_to_c2w`: returns (qvec wxyz, tvec)."""
    w2c = invert(c2w)
    return rot_to_quat(w2c[:3, :3]), w2c[:3, 3].copy()


def quat_to_rot(q: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) -> 3x3 rotation."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rot_to_quat(R: np.ndarray) -> np.ndarray:
    """3x3 rotation -> unit quaternion (w, x, y, z) with w >= 0."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    q = np.array([w, x, y, z])
    return q if q[0] >= 0 else -q


# ScanNet++ nerfstudio transforms.json: starting from the OpenCV c2w in the mesh frame, the y and z
# camera columns are negated, then rows x and y are swapped and row z negated (formats-facts.md).
def nerfstudio_scannetpp_to_c2w(T: np.ndarray) -> np.ndarray:
    """Undo ScanNet++'s nerfstudio pose convention -> OpenCV c2w in the mesh frame."""
    T = np.asarray(T, float).copy()
    T[2, :] *= -1
    T = T[[1, 0, 2, 3], :]
    T[0:3, 1:3] *= -1
    return T


def c2w_to_nerfstudio_scannetpp(c2w: np.ndarray) -> np.ndarray:
    """Apply ScanNet++'s nerfstudio convention (used by writers and tests)."""
    T = np.asarray(c2w, float).copy()
    T[0:3, 1:3] *= -1
    T = T[[1, 0, 2, 3], :]
    T[2, :] *= -1
    return T


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray = np.array([0.0, 0.0, 1.0])) -> np.ndarray:
    """OpenCV camera-to-world looking from ``eye`` at ``target`` with world ``up`` (z)."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    if np.linalg.norm(x) < 1e-8:
        x = np.cross(z, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, eye
    return T
