"""Photo-like shading of ray-cast synthetic frames (``realism="photo"``).

Flat vertex colours plus white noise taught image detectors things photos never show, so the photo
renderer adds what real captures have, all vectorized over the hit pixels:

- materials (per face): wood grain (a warped ring pattern fixed on the surface, so every view sees the
  same grain), glossy single colours and metal handles with Blinn-Phong highlights of the room lights
  plus a Fresnel-weighted reflection of the room (view-dependent: highlights move between views),
  matte paint with a faint roller texture, speckled stone worktops;
- light falloff: point lights on the ceiling and a lamp at 1.3 m, intensity ~ 1/r^2, and lens
  vignetting;
- crevice darkening: a pixel lying behind the planes of the surfaces on *both* sides of it (the 4 mm
  gap between two fronts, seen edge-on) is darkened like the ambient occlusion that makes real seams
  show as thin dark lines;
- per-frame exposure and white balance changes, mild linear motion blur, signal-dependent sensor
  noise, and an optional constant colour/depth misregistration (colour shifted by (dx, dy) pixels,
  like an imperfectly calibrated Kinect; depth, poses and GT part-id images stay registered).

Textures are a fixed tileable noise image looked up (cv2.remap) at planar coordinates of the world
hit point, so they stick to surfaces and the same seed gives the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

MATTE, WOOD, GLOSSY, METAL, STONE, GLASS = 0, 1, 2, 3, 4, 5
MATERIAL_NAMES = ("matte", "wood", "glossy", "metal", "stone", "glass")
REALISM = ("plain", "photo")

# per material: broad lobe (ks, shininess), sharp lobe (ks, shininess), Fresnel f0, room-reflection strength
_SPEC = np.array([
    [0.02, 8.0, 0.00, 1.0, 0.00, 0.0],     # matte paint
    [0.06, 20.0, 0.10, 150.0, 0.03, 0.25],  # lacquered wood
    [0.20, 40.0, 0.90, 600.0, 0.05, 0.90],  # glossy lacquer / laminate
    [0.45, 25.0, 0.80, 200.0, 0.50, 0.70],  # metal handles
    [0.08, 30.0, 0.30, 300.0, 0.04, 0.40],  # polished stone
    [0.00, 1.0, 1.00, 900.0, 0.06, 1.00],   # glass (only its reflection is drawn: see GlassLayer)
], np.float32)


@dataclass(frozen=True)
class GlassLayer:
    """Glass panes in front of the rendered surface: per pixel whether the first hit is glass, and that
    hit's normal and point (H, W, 3) and the pane's tint (H, W, 3 in 0..1). The image is shaded from
    what lies behind the glass; the pane lets ``tint`` x (1 - Fresnel) of it through and adds a
    Fresnel-weighted reflection of the room and sharp highlights of the lights (no refraction)."""

    mask: np.ndarray
    normal: np.ndarray
    point: np.ndarray
    tint: np.ndarray


@dataclass(frozen=True)
class PhotoSettings:
    """Scene-wide settings of the photo renderer (per-frame effects are drawn from the frame's generator)."""

    lights: np.ndarray                      # (L, 4): world x, y, z and relative power
    misregister: tuple[float, float] = (0.0, 0.0)  # colour shift vs depth in pixels of the RGB image
    blur_px: float = 2.5                    # motion-blur length is uniform in [0, blur_px]
    exposure_sigma: float = 0.15            # log-normal per-frame exposure gain


def scene_lights(room: tuple[float, float, float]) -> np.ndarray:
    """Two ceiling lights and a weaker lamp at 1.3 m in the middle of a W x L x H room (its low
    position puts highlights on base-cabinet fronts; lights near a wall would blow it out)."""
    W, L, H = room
    return np.array([[0.3 * W, 0.4 * L, H - 0.05, 1.0],
                     [0.7 * W, 0.6 * L, H - 0.05, 1.0],
                     [0.5 * W, 0.5 * L, 1.3, 0.5]], np.float32)


_TEX_SIZE = 512
_TEX: np.ndarray | None = None


def noise_texture() -> np.ndarray:
    """A tileable (periodic) 512x512 noise texture, 3 channels of unit-variance noise with feature sizes of
    ~16, ~4 and ~1 texels (low-pass filtered white noise in the Fourier domain; fixed seed, built once)."""
    global _TEX
    if _TEX is None:
        rng = np.random.default_rng(20261124)
        fy = np.fft.fftfreq(_TEX_SIZE)[:, None]
        fx = np.fft.fftfreq(_TEX_SIZE)[None, :]
        r2 = fx * fx + fy * fy
        chans = []
        for size in (16.0, 4.0, 1.0):
            white = rng.standard_normal((_TEX_SIZE, _TEX_SIZE))
            c = np.fft.ifft2(np.fft.fft2(white) * np.exp(-2.0 * (np.pi * size) ** 2 * r2 / 4.0)).real
            chans.append((c - c.mean()) / c.std())
        _TEX = np.ascontiguousarray(np.stack(chans, -1).astype(np.float32))
    return _TEX


def texture_lookup(a: np.ndarray, b: np.ndarray, texel_a: float, texel_b: float | None = None,
                   offset: float = 0.0) -> np.ndarray:
    """The noise texture at surface coordinates (a, b) in metres (one texel = ``texel_a`` x ``texel_b`` m),
    bilinear and wrapped: (..., 3)."""
    tb = texel_a if texel_b is None else texel_b
    mx = (a / texel_a + offset).astype(np.float32)
    my = (b / tb + 0.37 * offset).astype(np.float32)
    return cv2.remap(noise_texture(), mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)


def planar_coords(p: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Surface coordinates of channel-first points ``p`` (3, ...) on faces with normals ``n``: the two
    world axes other than the normal's dominant one ((x, y) on floors, (y, z) or (x, z) on walls and
    fronts, so ``b`` is height on vertical faces), and whether the face is horizontal."""
    ax, ay, az = np.abs(n[0]), np.abs(n[1]), np.abs(n[2])
    horiz = (az >= ax) & (az >= ay)
    xdom = (ax > ay) & ~horiz
    a = np.where(xdom, p[1], p[0])
    b = np.where(horiz, p[1], p[2])
    return a, b, horiz


def albedo_modulation(p: np.ndarray, n: np.ndarray, mat: np.ndarray) -> np.ndarray:
    """Multiplicative texture per hit point (channel-first ``p``, ``n``): wood grain, roller texture, speckle."""
    a, b, horiz = planar_coords(p, n)
    fine = texture_lookup(a, b, 0.002)
    coarse = texture_lookup(a, b, 0.02, offset=101.0)
    mod = np.ones(a.shape, np.float32)
    sel = mat == WOOD
    if sel.any():
        # across-grain coordinate: horizontal on vertical boards (vertical grain), y on horizontal ones
        across = np.where(horiz, b, a)
        along = np.where(horiz, a, b)
        fib = texture_lookup(across, along, 0.0008, 0.02, offset=53.0)[..., 2]
        s = across + 0.006 * coarse[..., 1] + 0.0015 * fine[..., 0]
        ring = 0.5 + 0.5 * np.sin(2 * np.pi * s / 0.008 + 1.2 * coarse[..., 0])
        wood = 0.90 + 0.22 * ring ** 4 - 0.10 * ring ** 12 + 0.03 * fib + 0.03 * coarse[..., 2]
        mod = np.where(sel, wood, mod)
    mod = np.where(mat == MATTE, 1.0 + 0.012 * fine[..., 0] + 0.012 * coarse[..., 0], mod)
    mod = np.where(mat == GLOSSY, 1.0 + 0.006 * coarse[..., 0], mod)
    mod = np.where(mat == STONE, 1.0 + 0.14 * fine[..., 2] + 0.05 * fine[..., 0], mod)
    mod = np.where(mat == METAL, 1.0 + 0.03 * fine[..., 1], mod)
    return mod.astype(np.float32)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot product over the first axis of channel-first (3, ...) arrays (much faster than ``sum(-1)``)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def crevice_occlusion(point: np.ndarray, normal: np.ndarray, valid: np.ndarray, radii: tuple[int, ...] = (1, 2),
                      depth_scale: float = 0.004, max_recess: float = 0.05) -> np.ndarray:
    """Per pixel in [0, 1]: how far the hit lies behind the surfaces on both sides of it (seams, gaps).

    ``point`` and ``normal`` are channel-first (3, H, W), normals facing the camera. For each direction
    and radius, the pixel's point is tested against the tangent planes of the two opposite
    neighbours; the smaller of the two recesses counts, so only crevices (both sides in front) darken,
    not convex edges or silhouettes (a recess > ``max_recess`` is a different surface far behind).
    """
    H, W = valid.shape
    pad = max(radii)
    P = np.pad(point * valid, ((0, 0), (pad, pad), (pad, pad)), mode="edge")
    N = np.pad(normal * valid, ((0, 0), (pad, pad), (pad, pad)), mode="edge")
    V = np.pad(valid, pad, mode="constant")
    D = _dot(P, N)  # plane offset of every pixel's tangent plane
    c = P[:, pad:pad + H, pad:pad + W]
    best = np.zeros((H, W), np.float32)
    for r in radii:
        for dy, dx in ((0, r), (r, 0), (r, r), (r, -r)):
            rec = []
            for sy, sx in ((dy, dx), (-dy, -dx)):
                win = (slice(pad + sy, pad + sy + H), slice(pad + sx, pad + sx + W))
                h = D[win] - _dot(N[(slice(None), *win)], c)
                rec.append(np.where(V[win] & (h < max_recess), h, 0.0))
            best = np.maximum(best, np.minimum(rec[0], rec[1]))
    return (np.clip(best / depth_scale, 0.0, 1.0) * valid).astype(np.float32)


def _motion_blur(img: np.ndarray, length: float, angle: float) -> np.ndarray:
    """Linear motion blur of ``length`` pixels at ``angle`` (radians)."""
    if length < 1.0:
        return img
    k = int(np.ceil(length)) * 2 + 1
    ker = np.zeros((k, k), np.float32)
    c = k // 2
    dx, dy = 0.5 * length * np.cos(angle), 0.5 * length * np.sin(angle)
    cv2.line(ker, (int(round(c - dx)), int(round(c - dy))), (int(round(c + dx)), int(round(c + dy))), 1.0, 1, cv2.LINE_AA)
    return cv2.filter2D(img, -1, ker / ker.sum(), borderType=cv2.BORDER_REPLICATE)


def shift_image(img: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """Content moved by (+dx, +dy) pixels (sub-pixel: bilinear), borders replicated."""
    if dx == 0 and dy == 0:
        return img
    M = np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]], np.float32)
    return cv2.warpAffine(img, M, (img.shape[1], img.shape[0]), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)


@lru_cache(maxsize=4)
def _vignette(H: int, W: int) -> np.ndarray:
    """Lens light falloff towards the corners (0.7 in the corners)."""
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    r2n = ((xx - W / 2) ** 2 + (yy - H / 2) ** 2) / ((W / 2) ** 2 + (H / 2) ** 2)
    return (1.0 - 0.3 * r2n).astype(np.float32)


def _through_glass(img: np.ndarray, glass: GlassLayer, d: np.ndarray, settings: PhotoSettings) -> np.ndarray:
    """``img`` (H, W, 3, linear, before exposure) seen through the panes of ``glass``; ``d`` the
    channel-first unit view rays."""
    g = glass.mask
    dg = d[:, g]
    n = glass.normal[g].astype(np.float32).T
    n *= np.where(_dot(n, dg) > 0, np.float32(-1.0), np.float32(1.0))
    ndv = np.clip(-_dot(n, dg), 0.0, 1.0)
    f0, shine, refl = _SPEC[GLASS, 4], _SPEC[GLASS, 3], _SPEC[GLASS, 5]
    fres = f0 + (1.0 - f0) * (1.0 - ndv) ** 5
    rz = dg[2] + 2.0 * ndv * n[2]
    add = refl * fres * (0.45 + 0.35 * rz)  # the room reflected: brighter towards the ceiling lights
    p = glass.point[g].astype(np.float32).T
    for lx, ly, lz, power in settings.lights:
        L = np.array([lx, ly, lz], np.float32)[:, None] - p
        h = L / np.sqrt(_dot(L, L)) - dg
        h /= np.sqrt(_dot(h, h)) + 1e-9
        add += power * 0.8 * np.clip(_dot(n, h), 0.0, 1.0) ** shine
    out = img.copy()
    out[g] = img[g] * (glass.tint[g] * (1.0 - fres)[:, None]) + add[:, None]
    return out


def render_photo(hit: dict[str, np.ndarray], faces: np.ndarray, colors: np.ndarray, face_mat: np.ndarray,
                 settings: PhotoSettings, frame_rng: np.random.Generator, noise_rng: np.random.Generator,
                 face_colors: np.ndarray | None = None, glass: GlassLayer | None = None) -> np.ndarray:
    """Photo-like uint8 RGB image of one ray-cast frame (``hit`` from :meth:`RayCaster.cast`).

    Albedo is ``face_colors`` (per face) when given, else the vertex colours. ``noise_rng`` draws
    exactly what the plain renderer draws (one standard normal per channel), so the scene's depth
    noise, drawn after it from the same generator, is the same in both modes. ``glass``: panes in
    front of ``hit`` (which is then the surface behind them), see :class:`GlassLayer`.
    """
    face = hit["face"]
    ok = face >= 0
    H, W = face.shape
    fi = np.maximum(face, 0)
    # channel-first (3, H, W) for fast per-pixel dot products
    d = np.ascontiguousarray(hit["dir"].astype(np.float32).transpose(2, 0, 1))
    n = np.ascontiguousarray(hit["normal"].astype(np.float32).transpose(2, 0, 1))
    n *= np.where(_dot(n, d) > 0, np.float32(-1.0), np.float32(1.0))  # facing the camera
    p = np.ascontiguousarray(hit["point"].astype(np.float32).transpose(2, 0, 1))
    ao = crevice_occlusion(p, n, ok)
    if face_colors is not None:
        albedo = face_colors[fi].astype(np.float32) / np.float32(255.0)
    else:
        f = faces[fi]
        u, v = hit["uv"][..., :1], hit["uv"][..., 1:]
        c = colors.astype(np.float32) / np.float32(255.0)
        albedo = c[f[..., 0]] * (1.0 - u - v) + c[f[..., 1]] * u + c[f[..., 2]] * v
    mat = face_mat[fi].astype(np.int64)
    albedo *= albedo_modulation(p, n, mat)[..., None]
    ks1, sh1, ks2, sh2, f0, refl = (_SPEC[mat, k] for k in range(6))
    vdir = -d
    diffuse = 0.22 + 0.12 * (0.5 + 0.5 * n[2])  # ambient + sky-like fill from above
    spec = np.zeros((H, W), np.float32)
    for lx, ly, lz, power in settings.lights:
        L = np.array([lx, ly, lz], np.float32)[:, None, None] - p
        r2 = _dot(L, L)
        l = L / np.sqrt(r2)
        diffuse += 0.6 * np.clip(_dot(n, l), 0.0, None) * (power * 2.5 / (r2 + 0.8))
        h = l + vdir
        h /= np.sqrt(_dot(h, h)) + 1e-9
        ndh = _dot(n, h)
        lit = ndh > 0.75  # below, every lobe (shininess >= 8) is < 0.1 of its peak: skip the pow
        nl = np.clip(ndh[lit], 0.0, 1.0)
        spec[lit] += power * 0.6 * (ks1[lit] * nl ** sh1[lit] + ks2[lit] * nl ** sh2[lit])  # no 1/r^2: a reflection
    ndv = np.clip(_dot(n, vdir), 0.0, 1.0)
    fres = f0 + (1.0 - f0) * (1.0 - ndv) ** 5
    rz = d[2] + 2.0 * ndv * n[2]  # z of the reflected view ray
    spec += refl * fres * (0.35 + 0.3 * rz)
    occl = 1.0 - 0.85 * ao
    img = (albedo * (diffuse * occl)[..., None] + (spec * occl)[..., None]) * ok[..., None]
    if glass is not None and glass.mask.any():
        img = _through_glass(img, glass, d, settings)
    gain = np.float32(1.5 * np.exp(frame_rng.normal(0.0, settings.exposure_sigma)))
    wb = np.exp(frame_rng.normal(0.0, 0.03, 3)).astype(np.float32)
    img = img.astype(np.float32) * (gain * wb)[None, None] * _vignette(H, W)[..., None]
    img = np.clip(img, 0.0, 1.0) * np.float32(255.0)
    img = _motion_blur(img, float(frame_rng.uniform(0.0, settings.blur_px)), float(frame_rng.uniform(0.0, np.pi)))
    img = shift_image(img, *settings.misregister)
    noise = noise_rng.standard_normal(img.shape, dtype=np.float32)
    img += noise * (np.float32(1.2) + np.float32(0.012) * img)
    return np.clip(img, 0, 255).astype(np.uint8)
