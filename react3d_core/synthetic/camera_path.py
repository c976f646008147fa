"""A hand-held-like camera walk: two sweeps per furniture run (far and level, then near and oblique).

Each part is then seen in many frames from varied distances and angles, as in a phone scan.
"""

from __future__ import annotations

import numpy as np

from ..camera import look_at
from .procedural import ViewRun


def camera_walk(runs: list[ViewRun], n_frames: int, room_depths: list[float], rng: np.random.Generator) -> list[np.ndarray]:
    """``n_frames`` OpenCV camera-to-world poses spread over ``runs`` proportionally to their length.

    ``room_depths[i]`` is the free distance from run i's wall to the opposite wall (keeps cameras inside).
    """
    if not runs:
        raise ValueError("no furniture to look at")
    lengths = np.array([r.x1 - r.x0 + 1.0 for r in runs])
    counts = np.floor(n_frames * lengths / lengths.sum()).astype(int)
    counts[np.argmax(lengths)] += n_frames - counts.sum()
    poses: list[np.ndarray] = []
    for run, cnt, room_d in zip(runs, counts, room_depths):
        if cnt <= 0:
            continue
        n_far = (cnt + 1) // 2
        T = run.frame.T
        span = run.x1 - run.x0
        zc = 0.5 * (run.z0 + run.z1)
        max_dist = max(0.6, room_d - run.depth - 0.35)
        for k in range(cnt):
            far = k < n_far
            m = n_far if far else cnt - n_far
            t = ((k if far else k - n_far) + 0.5) / max(m, 1)
            ph = rng.uniform(-0.03, 0.03, 3)
            if far:
                cx = run.x0 - 0.3 + (span + 0.6) * t
                dist = min(max_dist, 1.8 + 0.15 * np.sin(2 * np.pi * t))
                cz = 1.55 + 0.08 * np.sin(3 * np.pi * t)
                tx = run.x0 + span * (0.2 + 0.6 * t)
                tz = zc
            else:
                cx = run.x1 + 0.3 - (span + 0.6) * t
                dist = min(max_dist, 1.2 + 0.1 * np.cos(2 * np.pi * t))
                cz = 1.3 + 0.1 * np.sin(2 * np.pi * t)
                tx = run.x0 + span * (0.85 - 0.7 * t) + 0.3 * np.sin(2 * np.pi * t)
                tz = run.z0 + (run.z1 - run.z0) * (0.4 + 0.25 * np.sin(3 * np.pi * t))
            eye = T[:3, :3] @ np.array([cx, -(run.depth + dist), cz]) + T[:3, 3] + ph
            tgt = T[:3, :3] @ np.array([tx, -0.5 * run.depth, tz]) + T[:3, 3]
            poses.append(look_at(eye, tgt))
    return poses
