"""What a depth sensor does with glass, dark and glossy surfaces (synthetic scenes).

Time-of-flight and structured-light sensors (phone LiDAR, Kinect, RealSense) measure light they sent
out and got back. So:

- **glass** sends almost all of it through: the reading is what lies behind the pane. Only close to
  normal incidence does the pane's specular reflection come back strongly enough to be measured
  (:func:`glass_returns`); a fused mesh therefore mostly lacks glass, as real scans do;
- **dark** (low-albedo) surfaces send too little back: no reading at all on black, some on dark grey,
  fewer at grazing angles (:func:`dark_dropout`, the generator's ``depth_dropout="dark"``);
- **glossy** surfaces send the light away from the sensor except near the mirror direction, where they
  saturate it: dark glossy fronts return less than dark matte ones, and any glossy surface drops a
  patch where the view is close to its normal.

Returns are patchy, not salt and pepper: a smooth noise fixed on the surface (the photo renderer's
texture, 6 cm features) shifts each spot's return up or down in every view, as the micro-structure of
a real surface does, plus independent per-pixel noise. All of it is drawn from the caller's
generator, so the same seed gives the same depth.
"""

from __future__ import annotations

import numpy as np

from .materials import GLASS, GLOSSY, METAL, planar_coords, texture_lookup

DEPTH_DROPOUT = ("none", "dark")
DARK_ALBEDO = 0.06        # linear albedo x incidence term at which half the pixels return
DARK_WIDTH = 0.45         # log-albedo width of the transition
SURFACE_NOISE = 1.1       # weight of the surface-fixed noise (in units of the logit)
PIXEL_NOISE = 0.6         # weight of independent per-pixel noise
GLOSSY_DIFFUSE = 0.6      # share of a glossy surface's albedo that scatters diffusely back
SPECULAR_COS = 0.985      # within ~10 deg of the normal a glossy surface saturates the sensor ...
SPECULAR_DROP = 0.6       # ... and this share of those pixels is lost
GLASS_RETURN_COS = 0.985  # glass returns only within ~10 deg of its normal ...
GLASS_RETURN = 0.35       # ... and then on this share of the pixels


def linear_albedo(face_colors: np.ndarray) -> np.ndarray:
    """Per face the linear luminance (0..1) of its sRGB base colour."""
    c = np.asarray(face_colors, np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return (lin @ np.array([0.2126, 0.7152, 0.0722])).astype(np.float32)


def _incidence(hit: dict[str, np.ndarray]) -> np.ndarray:
    """|cos| of the angle between each pixel's ray and the surface normal (0 where nothing is hit)."""
    return np.abs((hit["normal"] * hit["dir"]).sum(-1)).astype(np.float32)


def dark_dropout(hit: dict[str, np.ndarray], albedo: np.ndarray, face_mat: np.ndarray,
                 rng: np.random.Generator) -> np.ndarray:
    """Boolean per pixel: the sensor gets no reading (dark or glossy surface), see the module doc.

    ``hit``: :meth:`.render.RayCaster.cast` of the surface the sensor sees (behind any glass);
    ``albedo``: :func:`linear_albedo` per face; ``face_mat``: material id per face."""
    face = hit["face"]
    ok = face >= 0
    fi = np.maximum(face, 0)
    mat = face_mat[fi]
    glossy = np.isin(mat, (GLOSSY, METAL))
    cos = _incidence(hit)
    a = albedo[fi] * np.where(glossy, GLOSSY_DIFFUSE, 1.0) * (0.3 + 0.7 * cos)
    logit = np.log(np.maximum(a, 1e-6) / DARK_ALBEDO) / DARK_WIDTH
    p = hit["point"].transpose(2, 0, 1)
    u, v, _ = planar_coords(p, hit["normal"].transpose(2, 0, 1))
    logit = logit + SURFACE_NOISE * texture_lookup(u, v, 0.004, offset=211.0)[..., 0]
    logit = logit + PIXEL_NOISE * rng.standard_normal(face.shape).astype(np.float32)
    saturated = glossy & (cos > SPECULAR_COS) & (rng.random(face.shape) < SPECULAR_DROP)
    return ok & ((logit < 0.0) | saturated)


def glass_returns(front: dict[str, np.ndarray], glass_px: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Boolean per pixel: a glass pane in front (``glass_px``) returns the reading itself (near normal
    incidence only, see the module doc); elsewhere the sensor reads what lies behind it."""
    cos = _incidence(front)
    return glass_px & (cos > GLASS_RETURN_COS) & (rng.random(glass_px.shape) < GLASS_RETURN)


def is_glass(face: np.ndarray, face_mat: np.ndarray) -> np.ndarray:
    """Per pixel of a face-id image: the hit face is glass."""
    return (face >= 0) & (face_mat[np.maximum(face, 0)] == GLASS)
