"""Read and write Articulate3D ground truth: ``<scan>_parts.json`` and ``<scan>_artic.json``.

Movable parts = the pids listed in ``articulations``. Axes are normalised on read (sign arbitrary);
ranges are radians for rotation and metres for translation; everything is in the mesh frame.

Two optional annotation keys extend the format for parts a scan may lack (synthetic scenes write them
where a scan can miss surface: depth dropped on dark fronts, see docs/evaluation.md): ``obb`` (the
part's true box in the closed state: ``center``, ``axes`` (rows), ``extents``) and ``scanCoverage``
(the share of the part's observed opaque surface that the scan mesh holds, 0..1). Readers that do not
know them ignore them; files without them read as before.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..atomic import write_json
from ..data.parts import OBB, Articulation
from ..errors import InputError


@dataclass
class GTPart:
    """One annotated part; ``articulation`` is None for static parts (e.g. a handle)."""

    part_id: int
    label: str
    tri_indices: np.ndarray
    vert_indices: np.ndarray
    articulation: Articulation | None = None
    base: list[int] = field(default_factory=list)
    obb: OBB | None = None            # true box of the part (closed), where the annotation gives it
    coverage: float | None = None     # share of its observed surface the scan holds, where given

    @property
    def movable(self) -> bool:
        return self.articulation is not None


@dataclass
class GroundTruth:
    """All parts of one scan."""

    scene_id: str
    parts: list[GTPart]
    total_faces: int | None = None
    total_vertices: int | None = None

    @property
    def movable(self) -> list[GTPart]:
        return [p for p in self.parts if p.movable]

    def movable_vertex_sets(self, include_children: bool = True) -> dict[int, np.ndarray]:
        """Vertex ids of each movable part; with ``include_children`` a part includes parts below it
        in the label hierarchy (e.g. its handle), which move with it."""
        out: dict[int, np.ndarray] = {}
        for p in self.movable:
            ids = [p.vert_indices]
            if include_children:
                prefix = p.label + "."
                ids += [c.vert_indices for c in self.parts if c.label.startswith(prefix) and not c.movable]
            out[p.part_id] = np.unique(np.concatenate(ids)).astype(np.int64)
        return out


def _paths(gt_dir: Path, scene_id: str) -> tuple[Path, Path]:
    return gt_dir / f"{scene_id}_parts.json", gt_dir / f"{scene_id}_artic.json"


def find_scene_id(gt_dir: str | Path) -> str:
    """The scan id of the single ``*_parts.json`` in ``gt_dir``."""
    gt_dir = Path(gt_dir)
    found = sorted(gt_dir.glob("*_parts.json"))
    if not found:
        raise InputError(gt_dir, "no <scan>_parts.json found")
    if len(found) > 1:
        raise InputError(gt_dir, f"several *_parts.json found ({', '.join(p.name for p in found)}); name the scan")
    return found[0].name[: -len("_parts.json")]


def read_articulate3d(gt_dir: str | Path, scene_id: str | None = None) -> GroundTruth:
    """Read both files; clear errors for missing files, bad JSON or missing fields."""
    gt_dir = Path(gt_dir)
    scene_id = scene_id or find_scene_id(gt_dir)
    parts_p, artic_p = _paths(gt_dir, scene_id)
    parts_j = _load(parts_p)
    artic_j = _load(artic_p) if artic_p.exists() else {"data": {"articulations": []}}
    try:
        anns = parts_j["data"]["annotations"]
        stats = parts_j["data"].get("stats", {})
    except (KeyError, TypeError):
        raise InputError(parts_p, "expected data.annotations[]") from None
    arts: dict[int, dict] = {}
    try:
        for a in artic_j["data"]["articulations"]:
            arts[int(a["pid"])] = a
    except (KeyError, TypeError, ValueError):
        raise InputError(artic_p, "expected data.articulations[] with 'pid'") from None
    parts = []
    for i, a in enumerate(anns):
        try:
            pid = int(a["partId"])
            part = GTPart(
                part_id=pid,
                label=str(a.get("label", "")),
                tri_indices=np.asarray(a.get("triIndices", []), dtype=np.int64),
                vert_indices=np.asarray(a.get("vertIndices", []), dtype=np.int64),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(parts_p, f"annotation {i}: bad or missing field ({exc})") from None
        try:
            if "obb" in a:
                part.obb = OBB(center=a["obb"]["center"], axes=a["obb"]["axes"], extents=a["obb"]["extents"])
            if "scanCoverage" in a:
                part.coverage = float(a["scanCoverage"])
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(parts_p, f"annotation {i} (partId {pid}): bad obb or scanCoverage ({exc})") from None
        if pid in arts:
            art = arts[pid]
            try:
                jt = {"rotation": "revolute", "translation": "prismatic"}[art["type"]]
                part.articulation = Articulation(
                    joint_type=jt,
                    axis=art["axis"],
                    origin=art.get("origin", [0.0, 0.0, 0.0]),
                    lower=float(art.get("rangeMin", 0.0)),
                    upper=float(art.get("rangeMax", 0.0)),
                    limit_source="gt",
                )
            except KeyError as exc:
                raise InputError(artic_p, f"articulation pid {pid}: missing or unknown {exc}") from None
            except ValueError as exc:
                raise InputError(artic_p, f"articulation pid {pid}: {exc}") from None
            part.base = [int(b) for b in art.get("base", [])]
        parts.append(part)
    missing = set(arts) - {p.part_id for p in parts}
    if missing:
        raise InputError(artic_p, f"articulations reference unknown part ids {sorted(missing)}")
    return GroundTruth(scene_id, parts, stats.get("totalFaces"), stats.get("totalVertices"))


def write_articulate3d(gt_dir: str | Path, gt: GroundTruth) -> tuple[Path, Path]:
    """Write ``<scan>_parts.json`` and ``<scan>_artic.json`` (atomically)."""
    gt_dir = Path(gt_dir)
    parts_p, artic_p = _paths(gt_dir, gt.scene_id)
    anns = []
    for p in gt.parts:
        ann: dict = {
            "partId": int(p.part_id),
            "label": p.label,
            "triIndices": [int(x) for x in p.tri_indices],
            "vertIndices": [int(x) for x in p.vert_indices],
        }
        if p.obb is not None:
            ann["obb"] = {"center": [round(float(x), 6) for x in p.obb.center],
                          "axes": [[round(float(x), 6) for x in ax] for ax in p.obb.axes],
                          "extents": [round(float(x), 6) for x in p.obb.extents]}
        if p.coverage is not None:
            ann["scanCoverage"] = round(float(p.coverage), 4)
        anns.append(ann)
    stats = {"totalFaces": gt.total_faces, "totalVertices": gt.total_vertices, "totalParts": len(gt.parts)}
    arts = []
    for p in gt.parts:
        if p.articulation is None:
            continue
        a = p.articulation
        arts.append(
            {
                "pid": int(p.part_id),
                "type": "rotation" if a.joint_type == "revolute" else "translation",
                "base": [int(b) for b in p.base],
                "axis": list(a.axis),
                "origin": list(a.origin),
                "rangeMin": float(a.lower),
                "rangeMax": float(a.upper),
            }
        )
    write_json(parts_p, {"data": {"annotations": anns, "stats": stats}}, indent=None)
    write_json(artic_p, {"data": {"articulations": arts}}, indent=1)
    return parts_p, artic_p


def _load(path: Path) -> dict:
    if not path.is_file():
        raise InputError(path, "ground-truth file not found")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise InputError(path, f"not valid JSON ({exc})") from None
