"""scene-synthesizer kitchens: objects the library stacks on the same stretch of wall are dropped (their
doors would z-fight with the kept ones and could never be found); objects that only touch are kept."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from react3d_core.synthetic.from_scene_synthesizer import overlapping_objects


def _box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> np.ndarray:
    return np.array([lo, hi], float)


def test_stacked_objects_dropped_first_placed_wins() -> None:
    boxes = {
        "base": _box((0, 0, 0), (1, 0.6, 0.72)),
        "countertop": _box((0, 0, 0.70), (1, 0.6, 0.73)),  # sinks 2 cm into the base: the whole top box is
        "beside": _box((1, 0, 0), (2, 0.6, 0.72)),  # shared thickness 0 (touching)
        "wall": _box((0, 0.2, 1.3), (1, 0.6, 2.0)),
        "wall_right": _box((1, 0.2, 1.3), (2, 0.6, 2.0)),  # touches "wall"
        "corner": _box((1.997, 0.597, 1.3), (2.4, 1.0, 2.0)),  # a 3 mm x 3 mm column with "wall_right"
        "wall_again": _box((0, 0.2, 1.3), (1, 0.6, 2.0)),  # the same slot again
        "wall_long": _box((-0.5, 0.2, 1.3), (1.8, 0.6, 2.0)),  # spans the slot and more
    }
    dropped = overlapping_objects(boxes)
    assert list(dropped) == ["wall_again", "wall_long"]
    assert dropped["wall_again"] == ("wall", 1.0)
    assert dropped["wall_long"][0] == "wall"


def test_order_decides_which_object_stays() -> None:
    a, b = _box((0, 0, 0), (1, 1, 1)), _box((0.5, 0, 0), (1.5, 1, 1))  # half of either box is shared
    assert list(overlapping_objects({"a": a, "b": b})) == ["b"]
    assert list(overlapping_objects({"b": b, "a": a})) == ["a"]


def _part_boxes(layout) -> dict[str, tuple[str | None, np.ndarray]]:  # noqa: ANN001
    """Each movable part's closed-geometry box and the carcass it hangs on (its object)."""
    out = {}
    for p in layout.parts:
        sel = layout.face_keys == layout.key_ids[p.key]
        v = layout.mesh.vertices[np.unique(layout.mesh.faces[sel].ravel())]
        out[p.key] = (p.parent_key, np.stack([v.min(0), v.max(0)]))
    return out


def test_kitchen_210_has_no_stacked_fronts() -> None:
    """Seed 210 (held-apart TSDF set): the library puts wall cabinets 1-5 over the same 1 m of wall
    (13 of its 37 fronts in the same place as another's). Cabinets 2-5 go; no front of one object
    overlaps a front of another. One kitchen: ~15 s on 2 cores, almost all of it inside scene-synthesizer."""
    pytest.importorskip("scene_synthesizer")
    from react3d_core.synthetic.from_scene_synthesizer import build_scene_synthesizer

    layout = build_scene_synthesizer(seed=210, edge=0.2)  # coarse triangles: the boxes do not depend on them
    assert layout.extra["dropped_objects"] == ["wall_cabinet_2", "wall_cabinet_3", "wall_cabinet_4", "wall_cabinet_5"]
    boxes = _part_boxes(layout)
    assert len(boxes) == 24
    clashes = []
    for (ka, (oa, a)), (kb, (ob, b)) in itertools.combinations(boxes.items(), 2):
        if oa == ob:
            continue
        ext = np.clip(np.minimum(a[1], b[1]) - np.maximum(a[0], b[0]), 0.0, None)
        smaller = min(np.prod(a[1] - a[0]), np.prod(b[1] - b[0]))
        if np.prod(ext) > 0.05 * smaller:  # stricter than the filter's 10 %
            clashes.append((ka, kb, float(np.prod(ext) / smaller)))
    assert clashes == []
