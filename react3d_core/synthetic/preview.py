"""A contact sheet of a scene folder: RGB frames beside their GT part-id images (for people, not tests)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ..atomic import atomic_path


def part_colors(ids: np.ndarray) -> np.ndarray:
    """Stable pseudo-random colour per id (0 = black)."""
    ids = ids.astype(np.int64)
    img = np.stack([(ids * 37 + 50) % 255, (ids * 91 + 20) % 255, (ids * 151 + 90) % 255], -1).astype(np.uint8)
    img[ids == 0] = 0
    return img


def write_preview(scene_dir: str | Path, out_path: str | Path | None = None, n: int = 6, width: int = 320) -> Path:
    """``n`` evenly spaced frames as rows of (RGB | part ids); returns the PNG path."""
    scene_dir = Path(scene_dir)
    rgbs = sorted((scene_dir / "iphone" / "rgb").glob("*.jpg"))
    if not rgbs:
        raise FileNotFoundError(f"{scene_dir}: no iphone/rgb/*.jpg frames")
    pick = [rgbs[i] for i in np.unique(np.linspace(0, len(rgbs) - 1, n).round().astype(int))]
    tiles = []
    for p in pick:
        rgb = cv2.imread(str(p))
        h = round(rgb.shape[0] * width / rgb.shape[1])
        row = [cv2.resize(rgb, (width, h), interpolation=cv2.INTER_AREA)]
        ids_p = scene_dir / "iphone" / "gt_part_ids" / (p.stem + ".png")
        if ids_p.exists():
            ids = cv2.imread(str(ids_p), cv2.IMREAD_UNCHANGED)
            row.append(cv2.resize(part_colors(ids)[..., ::-1], (width, h), interpolation=cv2.INTER_NEAREST))
        tiles.append(np.concatenate(row, 1))
    half = (len(tiles) + 1) // 2
    cols = [np.concatenate(tiles[:half], 0), np.concatenate(tiles[half:] + [np.zeros_like(tiles[0])] * (2 * half - len(tiles)), 0)]
    sheet = np.concatenate(cols, 1) if len(tiles) > 1 else cols[0]
    out = Path(out_path) if out_path else scene_dir / "preview.png"
    with atomic_path(out) as tmp:
        cv2.imwrite(str(tmp), sheet)
    return out
