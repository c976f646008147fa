"""Every threshold lives in PipelineConfig with a description (issue 17 item 5): the heuristic's front
rules, facets, renders and image path, fusion's duplicate/claim thresholds and the other module
constants moved in keep their old values, and they reach the config dump (manifest, cache keys)."""

from __future__ import annotations

import pytest
from pydantic import BaseModel

from react3d_core.config import PipelineConfig, StageConfig


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


# the values these thresholds had as module constants, dataclass defaults and keyword defaults
# before they moved into the config (hand-written: a changed default must be a deliberate edit here)
OLD_DEFAULTS = {
    # FrontRules (perception/heuristic/fronts.py)
    "perception.heuristic.fronts.min_w": 0.12,
    "perception.heuristic.fronts.max_w": 1.3,
    "perception.heuristic.fronts.min_h": 0.1,
    "perception.heuristic.fronts.max_h": 2.3,
    "perception.heuristic.fronts.max_tilt": 0.25,
    "perception.heuristic.fronts.min_fill": 0.8,
    "perception.heuristic.fronts.handle_max_area": 0.03,
    "perception.heuristic.fronts.handle_depth": (0.002, 0.09),
    "perception.heuristic.fronts.drawer_max_h": 0.45,
    "perception.heuristic.fronts.flap_min_top": 1.2,
    "perception.heuristic.fronts.neighbour_gap": 0.03,
    "perception.heuristic.fronts.frame_max_width": 0.2,
    "perception.heuristic.fronts.frame_depth": (0.001, 0.03),
    "perception.heuristic.fronts.raised_depth": (-0.016, -0.003),
    "perception.heuristic.fronts.rim_depth": 0.03,
    "perception.heuristic.fronts.rim_margin": 0.02,
    # planar_facets keyword defaults (facets.py)
    "perception.heuristic.facet_weld_m": 0.001,
    "perception.heuristic.facet_max_angle_deg": 12.0,
    # HeuristicModel (backend.py): scale, n_probe, MIN_MASK_PX and the visibility counts
    "perception.heuristic.render_scale": 0.5,
    "perception.heuristic.n_probe": 24,
    "perception.heuristic.probe_view_px": 4,
    "perception.heuristic.probe_min_views": 2,
    "perception.heuristic.probe_min_px": 40,
    "perception.heuristic.min_mask_px": 150,
    # SlidingRules.min_parallel (sliding.py)
    "perception.heuristic.sliding_min_parallel": 0.97,
    # ImageFrontParams (image_fronts.py) and the image path's keyword defaults
    "perception.heuristic.plane_offset_tol": 0.025,
    "perception.heuristic.plane_angle_tol_deg": 12.0,
    "perception.heuristic.min_plane_area": 0.08,
    "perception.heuristic.plane_cell": 0.04,
    "perception.heuristic.plane_min_fragment_area": 0.03,
    "perception.heuristic.face_depth": (-0.02, 0.07),
    "perception.heuristic.outline_fill_px": 20,
    "perception.heuristic.protrusion_depth": (0.012, 0.09),
    # OrthoParams (orthophoto.py)
    "perception.heuristic.ortho_max_side_px": 1200,
    "perception.heuristic.ortho_min_cos": 0.3,
    "perception.heuristic.ortho_render_scale": 0.5,
    "perception.heuristic.ortho_erode_px": 3,
    "perception.heuristic.ortho_edge_jump": 0.05,
    "perception.heuristic.ortho_depth_tol": 0.03,
    "perception.heuristic.ortho_margin": 0.02,
    "perception.heuristic.calib_scale_range": (0.84, 1.12),
    "perception.heuristic.calib_shift_range_px": 16.0,
    "perception.heuristic.calib_min_gain": 0.2,
    # CellParams (front_cells.py)
    "perception.heuristic.min_front_side": 0.1,
    "perception.heuristic.handle_aspect": 2.2,
    "perception.heuristic.handle_background_win": 0.12,
    "perception.heuristic.cell_min_seen": 0.55,
    "perception.heuristic.max_clutter": 0.18,
    "perception.heuristic.handle_outline_margin": 0.02,
    "perception.heuristic.texture_factor": 3.0,
    "perception.heuristic.max_split_depth": 6,
    # fusion/segment.py DUPLICATE_IOU, CONTAINED (both of its uses); graph.py MAX_ANCHORS; proposals._distinct
    "fusion.duplicate_iou": 0.5,
    "fusion.duplicate_contained": 0.8,
    "fusion.claimed_share": 0.8,
    "fusion.max_anchors": 8,
    "fusion.distinct_jaccard": 0.95,
    # fusion/clip.py MAX_POINTS; scene_io/selection.py COVERAGE_VOXEL_M
    "clip.ransac_max_points": 2000,
    "frames.coverage_voxel_m": 0.05,
}


def test_moved_thresholds_keep_their_old_defaults() -> None:
    values = {name: value for name, _, value in _fields(PipelineConfig())}
    assert {k: values.get(k) for k in OLD_DEFAULTS} == OLD_DEFAULTS


def test_internal_parameter_carriers_are_built_from_the_config() -> None:
    """The image path's and the sliding rule's dataclasses, built from the default config, equal their
    own defaults (which are read from the config), and an override reaches them."""
    from react3d_core.config import HeuristicConfig
    from react3d_core.perception.heuristic.fronts import FrontRules
    from react3d_core.perception.heuristic.image_fronts import ImageFrontParams, params_from_config
    from react3d_core.perception.heuristic.sliding import SlidingRules, sliding_from_config

    h = HeuristicConfig()
    assert params_from_config(h) == ImageFrontParams()
    assert sliding_from_config(h) == SlidingRules()
    assert FrontRules() == h.fronts
    h2 = PipelineConfig().with_overrides({"perception": {"heuristic": {
        "max_clutter": 0.3, "ortho_min_cos": 0.4, "plane_cell": 0.05, "sliding_min_parallel": 0.9}}}).perception.heuristic
    p = params_from_config(h2)
    assert (p.cells.max_clutter, p.ortho.min_cos, p.plane_cell) == (0.3, 0.4, 0.05)
    assert sliding_from_config(h2).min_parallel == 0.9


@pytest.mark.parametrize("override", [
    {"perception": {"heuristic": {"fronts": {"drawer_max_h": 0.5}}}},
    {"perception": {"heuristic": {"facet_max_angle_deg": 10.0}}},
    {"perception": {"heuristic": {"min_mask_px": 100}}},
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
