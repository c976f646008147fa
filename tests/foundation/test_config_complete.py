"""Every threshold lives in PipelineConfig, once, with a description: the code reads the config sections
themselves (no dataclass, keyword default or adapter mirrors a config field), the heuristic holds no
unnamed threshold literal, the defaults keep their values, an override reaches the code, and an old
flat key of ``perception.heuristic`` is rejected with its new name."""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any, Iterator

import pytest
from pydantic import BaseModel

from react3d_core.config import PipelineConfig, StageConfig

CORE = Path(__file__).resolve().parents[2] / "react3d_core"
HEURISTIC = CORE / "perception" / "heuristic"


def _fields(model: BaseModel, prefix: str = ""):
    """(dotted name, FieldInfo, value) of every field of ``model`` and of its nested sections."""
    for name, info in type(model).model_fields.items():
        value = getattr(model, name)
        yield prefix + name, info, value
        if isinstance(value, StageConfig):
            yield from _fields(value, prefix + name + ".")


def test_every_field_has_a_description() -> None:
    missing = [name for name, info, _ in _fields(PipelineConfig()) if not (info.description or "").strip()]
    assert missing == []


# --- (a) no mirrors: each config field is declared once, and the code takes the sections themselves ---

def _plain(value: Any) -> Any:
    """A config value or a literal as a comparable plain value (tuples/lists alike, bools apart from ints)."""
    if isinstance(value, list | tuple):
        return ("seq", tuple(_plain(v) for v in value))
    if isinstance(value, bool):
        return ("bool", value)
    if isinstance(value, int | float):
        return ("num", float(value))
    return ("other", value)


def config_leaves(config: BaseModel) -> tuple[dict[tuple[str, Any], list[str]], dict[str, set[str]]]:
    """(field name, plain default) -> the dotted config names declaring it; and each section's field names."""
    leaves: dict[tuple[str, Any], list[str]] = {}
    sections: dict[str, set[str]] = {"": set(type(config).model_fields)}
    for dotted, _, value in _fields(config):
        if isinstance(value, StageConfig):
            sections[dotted] = set(type(value).model_fields)
        elif value is not None and not isinstance(value, str):
            leaves.setdefault((dotted.rsplit(".", 1)[-1], _plain(value)), []).append(dotted)
    return leaves, sections


def _literal(node: ast.AST | None) -> Any:
    try:
        return ast.literal_eval(node) if node is not None else None
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return None


def _is_record_class(node: ast.ClassDef) -> bool:
    """A dataclass, a pydantic model or a NamedTuple: a class whose annotated fields are parameters."""
    decos = {ast.unparse(d).split("(")[0].rsplit(".", 1)[-1] for d in node.decorator_list}
    bases = {ast.unparse(b).rsplit(".", 1)[-1] for b in node.bases}
    return "dataclass" in decos or bool(bases & {"BaseModel", "StageConfig", "NamedTuple"})


def find_mirrors(source: str, where: str, config: BaseModel) -> list[str]:
    """Mirrors of ``config`` in one module's source: record-class fields and keyword defaults whose
    name and literal value are a config field's, functions named ``*_from_config``, and record classes
    whose defaulted fields (parameters, not results) are mostly one config section's (three or more)."""
    leaves, sections = config_leaves(config)
    out = []

    def check(name: str, node: ast.AST | None, line: int) -> None:
        value = _literal(node)
        if value is None or isinstance(value, str):
            return
        hit = leaves.get((name, _plain(value)))
        if hit:
            out.append(f"{where}:{line}: {name}={value!r} mirrors {', '.join(hit)}")

    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            if node.name.endswith("_from_config"):
                out.append(f"{where}:{node.lineno}: {node.name} copies config fields (read the section instead)")
            a = node.args
            positional = a.posonlyargs + a.args
            for arg, default in zip(positional[len(positional) - len(a.defaults):], a.defaults):
                check(arg.arg, default, node.lineno)
            for arg, default in zip(a.kwonlyargs, a.kw_defaults):
                check(arg.arg, default, node.lineno)
        elif isinstance(node, ast.ClassDef) and _is_record_class(node):
            names, defaulted = set(), set()
            for stmt in node.body:
                if isinstance(stmt, ast.AnnAssign) and isinstance(stmt.target, ast.Name):
                    names.add(stmt.target.id)
                    if stmt.value is not None:
                        defaulted.add(stmt.target.id)
                    check(stmt.target.id, stmt.value, stmt.lineno)
            for section, fields in sections.items():
                shared = defaulted & fields
                if len(shared) >= 3 and 2 * len(shared) >= len(names):
                    out.append(f"{where}:{node.lineno}: class {node.name} mirrors config section "
                               f"{section or 'PipelineConfig'} ({', '.join(sorted(shared))})")
    return out


def _core_modules() -> Iterator[Path]:
    for path in sorted(CORE.rglob("*.py")):
        if (CORE / "config") not in path.parents:  # the config package is where fields are declared
            yield path


# found outside the heuristic, in other stages' code (module, name): left to those stages, listed so
# that any new mirror fails the test
OUTSIDE_THE_HEURISTIC = {
    ("react3d_core/articulation/candidate.py", "refine"): "keyword default of refine_articulation = articulation.refine",
    ("react3d_core/fusion/graph.py", "max_anchors"): "keyword defaults = fusion.max_anchors",
    ("react3d_core/metrics/geometry.py", "horizontal_deg"): "keyword default of joint_class = evaluation.horizontal_deg",
    ("react3d_core/texture/writers.py", "png_compression"): "keyword defaults = export.png_compression",
    ("react3d_core/texture/writers.py", "jpeg_quality"): "keyword defaults = export.jpeg_quality",
    # same name and value, another quantity
    ("react3d_core/articulation/upright.py", "max_tilt"): "the articulation's upright box, not the heuristic's fronts",
    ("react3d_core/metrics/box_labels.py", "depth_tol"): "the box metric's visibility test, not the orthophotos'",
    ("react3d_core/synthetic/__init__.py", "seed"): "a generator's seed",
    ("react3d_core/synthetic/builder.py", "seed"): "a generator's seed",
    ("react3d_core/synthetic/from_scene_synthesizer.py", "seed"): "a generator's seed",
    ("react3d_core/synthetic/from_urdf.py", "seed"): "a generator's seed",
}


def test_no_config_field_is_mirrored_in_the_code() -> None:
    config = PipelineConfig()
    mirrors = []
    for path in _core_modules():
        where = str(path.relative_to(CORE.parent))
        mirrors += [m for m in find_mirrors(path.read_text(), where, config)
                    if (where, m.split(": ", 1)[1].split("=", 1)[0]) not in OUTSIDE_THE_HEURISTIC]
    assert mirrors == []
    assert not any("/perception/heuristic/" in where for where, _ in OUTSIDE_THE_HEURISTIC)


def test_the_mirror_check_catches_copies() -> None:
    """The check above can fail: a parameter dataclass copying a section, a keyword default repeating a
    threshold and an adapter are each reported."""
    source = '''
from dataclasses import dataclass

@dataclass(frozen=True)
class SlidingRules:
    max_overlap: float = 0.12
    max_gap: float = 0.02
    min_parallel: float = 0.97

def partner(f, fronts, min_height_overlap: float = 0.9):
    pass

def sliding_from_config(cfg):
    return SlidingRules(cfg.max_overlap, cfg.max_gap, cfg.min_parallel)
'''
    found = find_mirrors(source, "mod.py", PipelineConfig())
    assert any("class SlidingRules mirrors config section perception.heuristic.sliding" in m for m in found)
    assert any("max_overlap=0.12 mirrors perception.heuristic.sliding.max_overlap" in m for m in found)
    assert any("min_height_overlap=0.9 mirrors perception.heuristic.sliding.min_height_overlap" in m for m in found)
    assert any("sliding_from_config copies config fields" in m for m in found)
    assert find_mirrors("def f(x, min_parallel: float = 0.5):\n    pass\n", "mod.py", PipelineConfig()) == []


# --- (b) no unnamed threshold literals in the heuristic ---

# numbers that are no thresholds: none, one, two, halves (pixel centres, midpoints), division guards
ALLOWED_LITERALS = {0, 1, 2, -1, 0.5, 1e-9, 1e-12, 1e-15}


def threshold_literals(source: str, where: str) -> list[str]:
    """Numeric literals outside ``ALLOWED_LITERALS``, except in module-level constant assignments (named,
    with their comment) and in subscripts (array indices and axes)."""
    tree = ast.parse(source)
    exempt: set[int] = set()
    for stmt in tree.body:
        if isinstance(stmt, ast.Assign | ast.AnnAssign):
            exempt.update(id(n) for n in ast.walk(stmt))
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript):
            exempt.update(id(n) for n in ast.walk(node.slice))
    return [f"{where}:{node.lineno}: {node.value!r}" for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and type(node.value) in (int, float)
            and node.value not in ALLOWED_LITERALS and id(node) not in exempt]


def test_the_heuristic_has_no_unnamed_thresholds() -> None:
    """Every threshold of the heuristic is a config field (with a description) or a named module
    constant (unit conversions, array layouts, statistics constants)."""
    found = [hit for path in sorted(HEURISTIC.glob("*.py"))
             for hit in threshold_literals(path.read_text(), path.name)]
    assert found == []


def test_the_literal_check_catches_a_threshold() -> None:
    source = "LIMIT = 0.37  # named\n\ndef f(x, a):\n    y = a[:3, 3] * 0.5\n    if x > 0.37:\n        return 2 * y\n"
    assert threshold_literals(source, "mod.py") == ["mod.py:5: 0.37"]


# --- (c) defaults: a changed default is a deliberate edit of this table ---

# hand-written: every threshold of the heuristic (its earlier flat keys renamed into sections; the
# literals that were inline in the code, same values) and the other moved thresholds
DEFAULTS = {
    "perception.heuristic.facets.weld_m": 0.001,
    "perception.heuristic.facets.max_angle_deg": 12.0,
    "perception.heuristic.probe.frames": 24,
    "perception.heuristic.probe.downscale": 4,
    "perception.heuristic.probe.view_px": 4,
    "perception.heuristic.probe.min_views": 2,
    "perception.heuristic.probe.min_px": 40,
    "perception.heuristic.render.scale": 0.5,
    "perception.heuristic.render.min_mask_px": 150,
    "perception.heuristic.fronts.min_w": 0.12,
    "perception.heuristic.fronts.max_w": 1.3,
    "perception.heuristic.fronts.min_h": 0.1,
    "perception.heuristic.fronts.max_h": 2.3,
    "perception.heuristic.fronts.max_tilt": 0.25,
    "perception.heuristic.fronts.min_fill": 0.8,
    "perception.heuristic.fronts.ring_min_fill": 0.15,
    "perception.heuristic.fronts.handle_max_area": 0.03,
    "perception.heuristic.fronts.handle_depth": (0.002, 0.09),
    "perception.heuristic.fronts.handle_min_cos": -0.3,
    "perception.heuristic.fronts.rect_slack": 0.005,
    "perception.heuristic.fronts.parallel_cos": 0.97,
    "perception.heuristic.fronts.coplanar_offset": 0.03,
    "perception.heuristic.fronts.neighbour_align": 0.05,
    "perception.heuristic.fronts.cover_depth": (0.001, 0.08),
    "perception.heuristic.fronts.drawer_max_h": 0.45,
    "perception.heuristic.fronts.drawer_travel": 0.3,
    "perception.heuristic.fronts.flap_min_top": 1.2,
    "perception.heuristic.fronts.flap_max_h": 1.2,
    "perception.heuristic.fronts.flap_max_deg": 90.0,
    "perception.heuristic.fronts.door_max_deg": 100.0,
    "perception.heuristic.fronts.neighbour_gap": 0.03,
    "perception.heuristic.fronts.knob_max_aspect": 2.0,
    "perception.heuristic.fronts.knob_max_size": 0.07,
    "perception.heuristic.fronts.knob_centre": 0.25,
    "perception.heuristic.fronts.row_overlap": 0.01,
    "perception.heuristic.fronts.row_min_height_share": 0.7,
    "perception.heuristic.fronts.row_door_min_h": 0.5,
    "perception.heuristic.fronts.frame_max_width": 0.2,
    "perception.heuristic.fronts.frame_max_gap": 0.015,
    "perception.heuristic.fronts.frame_claim_margin": 0.003,
    "perception.heuristic.fronts.frame_min_sides": 3,
    "perception.heuristic.fronts.frame_panel_max_fill": 0.85,
    "perception.heuristic.fronts.frame_depth": (0.001, 0.03),
    "perception.heuristic.fronts.raised_depth": (-0.016, -0.003),
    "perception.heuristic.fronts.rim_depth": 0.03,
    "perception.heuristic.fronts.rim_front": 0.01,
    "perception.heuristic.fronts.rim_margin": 0.02,
    "perception.heuristic.floor.min_area": 0.5,
    "perception.heuristic.floor.band": 0.02,
    "perception.heuristic.floor.min_up": 0.9,
    "perception.heuristic.reach.drawer_max_top": 1.7,
    "perception.heuristic.lids.enabled": True,
    "perception.heuristic.lids.min_w": 0.7,
    "perception.heuristic.lids.min_up": 0.9,
    "perception.heuristic.lids.band": 0.04,
    "perception.heuristic.lids.min_depth": 0.4,
    "perception.heuristic.lids.cover": 0.6,
    "perception.heuristic.lids.max_depth": 1.0,
    "perception.heuristic.lids.side": 0.2,
    "perception.heuristic.lids.side_cover": 0.3,
    "perception.heuristic.lids.lip": 0.08,
    "perception.heuristic.splashback.enabled": True,
    "perception.heuristic.splashback.min_z": 0.5,
    "perception.heuristic.splashback.band": 0.08,
    "perception.heuristic.splashback.reach": (0.03, 0.33),
    "perception.heuristic.splashback.cover": 0.2,
    "perception.heuristic.splashback.min_up": 0.7,
    "perception.heuristic.splashback.run_depth": (0.45, 0.8),
    "perception.heuristic.splashback.worktop_rise": 0.07,
    "perception.heuristic.splashback.wall_ring": 0.3,
    "perception.heuristic.splashback.wall_behind": (0.2, 1.0),
    "perception.heuristic.splashback.wall_share": 0.1,
    "perception.heuristic.agreement.subsets": 0,
    "perception.heuristic.agreement.min_iou": 0.3,
    "perception.heuristic.agreement.min_runs": 1,
    "perception.heuristic.agreement.min_frames": 10,
    "perception.heuristic.agreement.plane_cos": 0.94,
    "perception.heuristic.agreement.plane_gap": 0.05,
    "perception.heuristic.room_wall.enabled": True,
    "perception.heuristic.room_wall.behind_share": 0.005,
    "perception.heuristic.room_wall.depth": 0.1,
    "perception.heuristic.room_wall.min_area": 1.0,
    "perception.heuristic.room_wall.plane_tol": 0.03,
    "perception.heuristic.room_wall.plane_min_cos": 0.9,
    "perception.heuristic.room_wall.wall_back": 0.3,
    "perception.heuristic.room_wall.wall_band": 0.1,
    "perception.heuristic.room_wall.door_min_h": 1.8,
    "perception.heuristic.room_wall.door_w": (0.6, 1.3),
    "perception.heuristic.room_wall.door_floor_gap": 0.05,
    "perception.heuristic.sliding.track_offset": (0.008, 0.06),
    "perception.heuristic.sliding.max_overlap": 0.12,
    "perception.heuristic.sliding.max_gap": 0.02,
    "perception.heuristic.sliding.min_height_overlap": 0.9,
    "perception.heuristic.sliding.min_parallel": 0.97,
    "perception.heuristic.sliding.min_travel": 0.05,
    "perception.heuristic.image.enabled": True,
    "perception.heuristic.image.texture_factor": 3.0,
    "perception.heuristic.image.face_depth": (-0.02, 0.07),
    "perception.heuristic.image.surface_rays": False,
    "perception.heuristic.image.seen_reach": 0.05,
    "perception.heuristic.image.rays_face_edge": 0.015,
    "perception.heuristic.image.modelled_share": 0.5,
    "perception.heuristic.image.coverage_tilt_deg": 0.0,
    "perception.heuristic.image.coverage_tilt_depth": 0.025,
    "perception.heuristic.image.coverage_close": 0.02,
    "perception.heuristic.image.outline_fill_px": 20,
    "perception.heuristic.image.min_faces": 4,
    "perception.heuristic.image.pane_frame": 0.035,
    "perception.heuristic.image.pane_cell_cover": True,
    "perception.heuristic.image.pane_frame_cover": 0.85,
    "perception.heuristic.image.pane_min_area": 0.01,
    "perception.heuristic.image.pane_min_side": 0.1,
    "perception.heuristic.image.pane_min_fill": 0.8,
    "perception.heuristic.image.pane_solid_share": 0.5,
    "perception.heuristic.image.pane_solid_depth": 0.015,
    "perception.heuristic.image.pane_seen": True,
    "perception.heuristic.image.pane_seen_reach": 0.035,
    "perception.heuristic.image.pane_seen_max_cover": 0.9,
    "perception.heuristic.image.pane_seen_rim": 0.035,
    "perception.heuristic.image.pane_seen_rim_sides": False,
    "perception.heuristic.image.pane_speck": 0.02,
    "perception.heuristic.image.pane_gap": 0.08,
    "perception.heuristic.image.pane_rounds": 3,
    "perception.heuristic.image.pane_bar": 0.02,
    "perception.heuristic.image.glass_behind": 0.8,
    "perception.heuristic.image.glass_behind_min": 0.03,
    "perception.heuristic.image.glass_behind_share": 0.5,
    "perception.heuristic.image.glass_behind_grow": 0.09,
    "perception.heuristic.image.pane_fill": True,
    "perception.heuristic.image.pane_edge": 0.02,
    "perception.heuristic.image.mesh_share": 0.3,
    "perception.heuristic.image.plain_floor_gap": 0.03,
    "perception.heuristic.image.veto_plane_offset": 0.08,
    "perception.heuristic.image.veto_min_px": 5,
    "perception.heuristic.image.veto_min_seen": 0.3,
    "perception.heuristic.planes.offset_tol": 0.025,
    "perception.heuristic.planes.angle_tol_deg": 12.0,
    "perception.heuristic.planes.direction_smooth_bins": 5,
    "perception.heuristic.planes.direction_min_sep_bins": 6,
    "perception.heuristic.planes.direction_peak_div": 5.0,
    "perception.heuristic.planes.offset_bin": 0.005,
    "perception.heuristic.planes.offset_peak_div": 10.0,
    "perception.heuristic.planes.refit_deg": 3.0,
    "perception.heuristic.planes.refit_min_gain": 1.4,
    "perception.heuristic.planes.refit_keep_share": 0.9,
    "perception.heuristic.planes.refit_min_extent": 1.0,
    "perception.heuristic.planes.refit_run_step": 0.04,
    "perception.heuristic.planes.refit_step_deg": 0.1,
    "perception.heuristic.planes.refit_bin": 0.002,
    "perception.heuristic.planes.refit_sigma": 0.003,
    "perception.heuristic.planes.max_skew_deg": 5.0,
    "perception.heuristic.planes.normal_agree": 0.5,
    "perception.heuristic.planes.revote_rounds": 1,
    "perception.heuristic.planes.smooth_rings": 0,
    "perception.heuristic.planes.smooth_peak_div": 10.0,
    "perception.heuristic.planes.min_area": 0.05,
    "perception.heuristic.planes.residual_dip": 0.0,
    "perception.heuristic.planes.residual_stack_depth": 0.08,
    "perception.heuristic.planes.residual_max_stack": 0.5,
    "perception.heuristic.planes.cell": 0.04,
    "perception.heuristic.planes.min_fragment_area": 0.03,
    "perception.heuristic.planes.slope_win": 0.012,
    "perception.heuristic.ortho.resolution": 0.004,
    "perception.heuristic.ortho.max_side_px": 1200,
    "perception.heuristic.ortho.max_views": 30,
    "perception.heuristic.ortho.pick_spread": False,
    "perception.heuristic.ortho.pick_samples": 9,
    "perception.heuristic.ortho.pick_need": 8,
    "perception.heuristic.ortho.pick_sep": 0.15,
    "perception.heuristic.ortho.pick_sep_deg": 10.0,
    "perception.heuristic.ortho.min_cos": 0.3,
    "perception.heuristic.ortho.render_scale": 0.5,
    "perception.heuristic.ortho.erode_px": 3,
    "perception.heuristic.ortho.edge_jump": 0.05,
    "perception.heuristic.ortho.depth_tol": 0.03,
    "perception.heuristic.ortho.depth_tol_rel": 0.01,
    "perception.heuristic.ortho.min_view_px": 50,
    "perception.heuristic.ortho.margin": 0.02,
    "perception.heuristic.calibration.enabled": True,
    "perception.heuristic.calibration.scale_range": (0.84, 1.12),
    "perception.heuristic.calibration.scale_steps": 15,
    "perception.heuristic.calibration.shift_range_px": 16.0,
    "perception.heuristic.calibration.shift_steps": 5,
    "perception.heuristic.calibration.fine_scales": (-0.02, -0.01, 0.01, 0.02),
    "perception.heuristic.calibration.fine_shift_px": 3.0,
    "perception.heuristic.calibration.planes": 2,
    "perception.heuristic.calibration.max_views": 12,
    "perception.heuristic.calibration.min_views": 3,
    "perception.heuristic.calibration.min_px": 100,
    "perception.heuristic.calibration.min_gain": 0.2,
    "perception.heuristic.registration.sigmas_px": (),
    "perception.heuristic.registration.prior_scale": 0.08,
    "perception.heuristic.registration.prior_shift_px": 30.0,
    "perception.heuristic.registration.rounds": 2,
    "perception.heuristic.registration.iters": 3,
    "perception.heuristic.registration.min_views": 3,
    "perception.heuristic.registration.min_points": 2000,
    "perception.heuristic.registration.band": 2.0,
    "perception.heuristic.registration.reach": 2.0,
    "perception.heuristic.registration.min_gain": 0.1,
    "perception.heuristic.registration.max_scale_step": 0.02,
    "perception.heuristic.registration.converged_shift_px": 0.05,
    "perception.heuristic.registration.converged_scale": 1e-4,
    "perception.heuristic.seams.contrast": 0.01,
    "perception.heuristic.seams.width_px": 3,
    "perception.heuristic.seams.smooth_px": 9,
    "perception.heuristic.seams.span": 0.35,
    "perception.heuristic.seams.span_chunks": 3,
    "perception.heuristic.seams.prominence": 0.3,
    "perception.heuristic.seams.prominence_h": 0.5,
    "perception.heuristic.seams.dip_z": 15.0,
    "perception.heuristic.seams.piece_sides": 3,
    "perception.heuristic.seams.piece_contrast": 0.0005,
    "perception.heuristic.seams.min_line_cover": 0.3,
    "perception.heuristic.seams.noise_floor": 0.001,
    "perception.heuristic.seams.step_contrast": 0.25,
    "perception.heuristic.seams.ridges": True,
    "perception.heuristic.seams.step_z": 15.0,
    "perception.heuristic.seams.step_over_dip": True,
    "perception.heuristic.seams.between_z": 3.0,
    "perception.heuristic.seams.between_span": 0.2,
    "perception.heuristic.seams.knob_pair_gap": 0.3,
    "perception.heuristic.seams.knob_pair_centre": 0.1,
    "perception.heuristic.seams.knob_seam": True,
    "perception.heuristic.seams.clear_of_handles": True,
    "perception.heuristic.lines.enabled": True,
    "perception.heuristic.lines.detector": "lsd",
    "perception.heuristic.lines.gamma": 0.5,
    "perception.heuristic.lines.weights": None,
    "perception.heuristic.lines.threads": 2,
    "perception.heuristic.lines.min_score": 0.1,
    "perception.heuristic.lines.min_length_px": 40.0,
    "perception.heuristic.lines.max_frames": 24,
    "perception.heuristic.lines.views_per_plane": 6,
    "perception.heuristic.lines.max_angle_deg": 4.0,
    "perception.heuristic.lines.tol": 0.015,
    "perception.heuristic.lines.min_views": 2,
    "perception.heuristic.lines.span": 0.6,
    "perception.heuristic.handles.contrast": 0.12,
    "perception.heuristic.handles.length": (0.1, 0.6),
    "perception.heuristic.handles.strip_length": 0.5,
    "perception.heuristic.handles.thickness": (0.014, 0.07),
    "perception.heuristic.handles.aspect": 2.2,
    "perception.heuristic.handles.min_fill": 0.4,
    "perception.heuristic.handles.join_gap": 0.03,
    "perception.heuristic.handles.mesh_bar_parts": True,
    "perception.heuristic.handles.min_seen_px": 100,
    "perception.heuristic.handles.background_win": 0.12,
    "perception.heuristic.handles.outline_margin": 0.02,
    "perception.heuristic.handles.side_band": 0.02,
    "perception.heuristic.handles.around_cover": 0.4,
    "perception.heuristic.handles.side_cover": 0.4,
    "perception.heuristic.handles.hidden_side": 0.5,
    "perception.heuristic.handles.hidden_depth": 0.06,
    "perception.heuristic.handles.few_views": 0.2,
    "perception.heuristic.handles.protrusion_depth": (0.012, 0.09),
    "perception.heuristic.handles.protrusion_min_cos": 0.5,
    "perception.heuristic.handles.protrusion_from_surface": True,
    "perception.heuristic.handles.surface_block": 0.02,
    "perception.heuristic.handles.bar_close_px": 5,
    "perception.heuristic.handles.shadows": True,
    "perception.heuristic.handles.shadow_min_thick": 0.03,
    "perception.heuristic.handles.knobs": True,
    "perception.heuristic.handles.knob_size": (0.025, 0.065),
    "perception.heuristic.handles.knob_aspect": 1.6,
    "perception.heuristic.handles.knob_min_fill": 0.7,
    "perception.heuristic.handles.knob_pair": 0.02,
    "perception.heuristic.handles.knob_pair_size": 1.4,
    "perception.heuristic.handles.knob_pair_reach": 1.0,
    "perception.heuristic.handles.knob_panel_gap": 0.16,
    "perception.heuristic.handles.seam_share": 0.9,
    "perception.heuristic.handles.bar_plane_min": 2,
    "perception.heuristic.handles.bar_row": 0.0,
    "perception.heuristic.handles.bar_row_gap": 0.05,
    "perception.heuristic.handles.bar_share": 0.5,
    "perception.heuristic.handles.bar_reach": 0.0,
    "perception.heuristic.handles.pane_bar_reach": 0.1,
    "perception.heuristic.handles.proud_layer": 0.03,
    "perception.heuristic.handles.proud_gain": 2.0,
    "perception.heuristic.handles.proud_contrast": 1.2,
    "perception.heuristic.handles.proud_margin": 0.05,
    "perception.heuristic.handles.proud_near": 0.05,
    "perception.heuristic.cells.min_side": 0.1,
    "perception.heuristic.cells.max_split_depth": 6,
    "perception.heuristic.cells.pane_margin": 0.015,
    "perception.heuristic.cells.outline_step": 0.5,
    "perception.heuristic.cells.knobs_any_side": True,
    "perception.heuristic.cells.lone_knobs_block": True,
    "perception.heuristic.cells.edge_strip": 0.2,
    "perception.heuristic.cells.seams_past_handles": True,
    "perception.heuristic.cells.edge_pull": 0.012,
    "perception.heuristic.cells.groove_share": 0.3,
    "perception.heuristic.cells.groove_px": 8,
    "perception.heuristic.cells.groove_cover": 0.7,
    "perception.heuristic.cells.bar_pairs": True,
    "perception.heuristic.cells.pitch_tol": 0.1,
    "perception.heuristic.cells.sliver_max": 0.13,
    "perception.heuristic.cells.sliver_ratio": 1.5,
    "perception.heuristic.cells.min_seen": 0.55,
    "perception.heuristic.cells.seen_rim": True,
    "perception.heuristic.cells.min_tile_side": 0.25,
    "perception.heuristic.cells.min_tiles": 3,
    "perception.heuristic.cells.tile_edge_strips": False,
    "perception.heuristic.cells.strip_seams": False,
    "perception.heuristic.cells.handleless_min_seams": 2,
    "perception.heuristic.cells.stack_min": 3,
    "perception.heuristic.cells.single_cut": True,
    "perception.heuristic.cells.piece_max_w": 2.0,
    "perception.heuristic.cells.piece_behind": True,
    "perception.heuristic.cells.piece_fill": 0.6,
    "perception.heuristic.cells.piece_front_share": 0.5,
    "perception.heuristic.cells.piece_seen": 0.8,
    "perception.heuristic.cells.mesh_split_seams": True,
    "perception.heuristic.portholes.enabled": True,
    "perception.heuristic.portholes.diameter": (0.3, 0.6),
    "perception.heuristic.portholes.max_aspect": 1.25,
    "perception.heuristic.portholes.band": (0.55, 1.15),
    "perception.heuristic.portholes.ring_share": 0.85,
    "perception.heuristic.portholes.sectors": 0.75,
    "perception.heuristic.portholes.inner": 0.45,
    "perception.heuristic.portholes.inner_max": 0.1,
    "perception.heuristic.portholes.face_depth": (-0.02, 0.12),
    "perception.heuristic.portholes.plate_gap": 0.15,
    "perception.heuristic.portholes.bar_cuts": True,
    "perception.heuristic.clutter.max_share": 0.18,
    "perception.heuristic.clutter.max_share_handle": 0.3,
    "perception.heuristic.clutter.handle_rim": 0.03,
    "perception.heuristic.clutter.cell_median": True,
    "perception.heuristic.clutter.median_min_px": 50,
    "perception.heuristic.clutter.line_min_len": 0.15,
    "perception.heuristic.clutter.line_max_width": 0.02,
    # fusion/segment.py DUPLICATE_IOU, CONTAINED (both of its uses); graph.py MAX_ANCHORS; proposals._distinct
    "fusion.duplicate_iou": 0.5,
    "fusion.duplicate_contained": 0.8,
    "fusion.claimed_share": 0.8,
    "fusion.merge_instances": True,
    "fusion.lid_claims_skirt": True,
    "fusion.max_anchors": 8,
    "fusion.distinct_jaccard": 0.95,
    # fusion/clip.py MAX_POINTS; scene_io/selection.py COVERAGE_VOXEL_M
    "clip.ransac_max_points": 2000,
    "frames.coverage_voxel_m": 0.05,
    "frames.missed_surface.min_line_m": 0.3,
    "frames.missed_surface.line_clear_m": 0.1,
    "frames.missed_surface.line_gap_m": 0.05,
    "frames.missed_surface.line_fill": 0.5,
    "frames.missed_surface.line_axis_deg": 5.0,
    "frames.missed_surface.line_ahead_share": 0.2,
}


def test_defaults_are_unchanged() -> None:
    values = {name: value for name, _, value in _fields(PipelineConfig())}
    assert {k: values.get(k) for k in DEFAULTS} == DEFAULTS


def test_every_heuristic_threshold_is_in_the_defaults_table() -> None:
    heuristic = {name for name, _, value in _fields(PipelineConfig())
                 if name.startswith("perception.heuristic.") and not isinstance(value, StageConfig)}
    assert heuristic - set(DEFAULTS) == set()


# --- (d) an override reaches the code; old keys name their new place ---

def test_an_override_reaches_the_code() -> None:
    """``perception.heuristic.floor`` overridden in the pipeline config changes the floor the heuristic
    finds. Hand-computed: faces at z 0.00 (1 m²) and 0.03 (2 m²), facing up. In 2 cm bands the lowest
    band holds only the 1 m² at 0.00 -> floor 0.00 at min_area 0.5; at min_area 1.5 that band is too
    small and the next (0.03) is the floor; in 5 cm bands both lie in one band of 3 m² whose
    area-weighted median is 0.03."""
    import numpy as np

    from react3d_core.data.mesh import TriMesh
    from react3d_core.perception.heuristic.image_fronts import floor_height

    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 2, 0.03], [2, 2, 0.03], [2, 3, 0.03], [0, 3, 0.03]], float)
    mesh = TriMesh(v, np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]))

    def floor(override: dict) -> float | None:
        cfg = PipelineConfig().with_overrides({"perception": {"heuristic": {"floor": override}}})
        return floor_height(mesh, cfg.perception.heuristic.floor)

    assert floor({}) == pytest.approx(0.0)
    assert floor({"min_area": 1.5}) == pytest.approx(0.03)
    assert floor({"band": 0.05}) == pytest.approx(0.03)
    assert floor({"min_up": 1.0}) is None  # no face is more upward than straight up


@pytest.mark.parametrize("old, new", [
    ("handle_side_cover", "handles.side_cover"),
    ("ortho_resolution", "ortho.resolution"),
    ("seam_z", "seams.dip_z"),
    ("register_sigmas_px", "registration.sigmas_px"),
    ("splashback", "splashback.enabled"),
    ("room_wall", "room_wall.enabled"),
    ("image_fronts", "image.enabled"),
])
def test_an_old_flat_key_names_its_new_place(old: str, new: str) -> None:
    from react3d_core.errors import ConfigError

    value = False if old in ("splashback", "room_wall", "image_fronts") else 0.5
    with pytest.raises(ConfigError, match=f"perception.heuristic.{old} is now perception.heuristic.{new}"):
        PipelineConfig().with_overrides({"perception": {"heuristic": {old: value}}})


def test_every_old_key_maps_to_a_field() -> None:
    """``RENAMED`` names existing fields only (a renamed key's message must lead somewhere)."""
    from react3d_core.config.heuristic import RENAMED

    names = {name for name, _, _ in _fields(PipelineConfig().perception.heuristic)}
    assert sorted(set(RENAMED.values()) - names) == []
    assert not set(RENAMED) & names - {"splashback", "room_wall"}  # only the two switches became sections


@pytest.mark.parametrize("override", [
    {"perception": {"heuristic": {"fronts": {"drawer_max_h": 0.5}}}},
    {"perception": {"heuristic": {"facets": {"max_angle_deg": 10.0}}}},
    {"perception": {"heuristic": {"render": {"min_mask_px": 100}}}},
    {"fusion": {"duplicate_iou": 0.6}},
    {"clip": {"ransac_max_points": 1000}},
    {"frames": {"coverage_voxel_m": 0.1}},
])
def test_a_moved_threshold_changes_the_config_dump(override: dict) -> None:
    """The manifest records ``model_dump(mode="json")`` and the stage caches key on config sections:
    a changed threshold must show in both."""
    base, changed = PipelineConfig(), PipelineConfig().with_overrides(override)
    assert base.model_dump(mode="json") != changed.model_dump(mode="json")
    section = next(iter(override))
    assert getattr(base, section).model_dump(mode="json") != getattr(changed, section).model_dump(mode="json")


def test_unknown_front_rule_is_rejected() -> None:
    from react3d_core.errors import ConfigError

    with pytest.raises(ConfigError):
        PipelineConfig().with_overrides({"perception": {"heuristic": {"fronts": {"drawer_max": 0.5}}}})
