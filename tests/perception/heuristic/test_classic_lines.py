"""OpenCV's LSD as the line evidence's weight-free detector (perception/heuristic/classic_lines.py)."""

from __future__ import annotations

import numpy as np

from react3d_core.config.heuristic import HeuristicConfig, LineConfig
from react3d_core.perception.heuristic.classic_lines import lsd_segments


def _dark_seam_image(base: int = 30, seam: int = 22) -> np.ndarray:
    """A 640 x 480 black front (grey ``base``) with a 2 px seam ``base - seam`` levels darker at x 318-319, and
    sensor noise (sigma 1 level, seeded)."""
    img = np.full((480, 640, 3), float(base))
    img[:, 318:320] = seam
    img += np.random.default_rng(0).normal(0.0, 1.0, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def _along_seam(seg: np.ndarray) -> np.ndarray:
    return seg[(np.abs(seg[:, 0] - 318.5) < 3) & (np.abs(seg[:, 2] - 318.5) < 3)]


def test_lsd_finds_a_seam_between_black_fronts_only_when_the_dark_levels_are_lifted() -> None:
    """The seam is 8 grey levels deep on a front at 30: in the raw grey image LSD finds no segment (the gradient
    is under its quantisation bound); lifted by gamma 0.5 (30 -> 87, 22 -> 75: 12 levels) it finds vertical
    segments along the seam, the longest over 300 of the 480 rows. Segments are in image pixels."""
    img = _dark_seam_image()
    assert len(_along_seam(lsd_segments(img, 1.0, 40.0))) == 0
    seam = _along_seam(lsd_segments(img, 0.5, 40.0))
    assert len(seam) >= 1 and float(np.abs(seam[:, 3] - seam[:, 1]).max()) > 300


def test_short_segments_are_dropped_by_length_in_reference_pixels() -> None:
    """``min_length_px`` is in px of a 512 px wide image: on this 640 px one a 40 px bound is 50 px. A dark bar
    45 px long (x 100-144, rows 200-203 on a light image) passes at 30 (37.5 px here) and not at 40 (50 px)."""
    img = np.full((480, 640, 3), 200, np.uint8)
    img[200:204, 100:145] = 40
    assert len(lsd_segments(img, 1.0, 30.0)) >= 1
    assert len(lsd_segments(img, 1.0, 40.0)) == 0


def test_the_default_detector_is_lsd_and_loads_without_weights() -> None:
    from react3d_core.perception.heuristic.backend import load_line_detector

    assert LineConfig().detector == "lsd" and LineConfig().gamma == 0.5
    seg = load_line_detector(LineConfig())(_dark_seam_image())
    assert seg.ndim == 2 and seg.shape[1] == 4 and len(_along_seam(seg)) >= 1


def assert_seam_supported_and_two_doors(cfg: HeuristicConfig) -> None:
    """The two-door scene whose seam is only in the colours (test_image_fronts), its image fronts found with the
    detector ``cfg.lines`` names: the seam at x = 0.6 m is supported by at least ``min_views`` of 3 or more views
    read, and the two doors are found."""
    from react3d_core.perception.heuristic.backend import load_line_detector
    from react3d_core.perception.heuristic.image_fronts import find_image_fronts
    from react3d_core.raster import Rasterizer
    from tests.perception.heuristic.test_image_fronts import _seamless_cabinet_scene

    mesh, frames, images = _seamless_cabinet_scene()
    res = find_image_fronts(mesh, frames, Rasterizer(mesh), lambda f: images[f.frame_id], cfg,
                            detect_lines=load_line_detector(cfg.lines))
    i = min(range(len(res.planes)), key=lambda k: abs(res.planes[k].d))   # the doors' plane (y = 0)
    o, sup = res.orthophotos[i], res.lines[i]
    assert sup.n_views >= 3
    col = int((0.6 * np.sign(o.plane.u[0]) - o.u0) / o.res)
    assert sup.vert[:, col - 3:col + 4].max() >= cfg.lines.min_views
    assert len(res.fronts) == 2


def test_lsd_line_evidence_end_to_end() -> None:
    """With the default ``lines`` section (on, LSD) the two-door scene's seam is supported and both doors found."""
    assert_seam_supported_and_two_doors(HeuristicConfig())
