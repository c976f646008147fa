"""The whole method as plain functions: ``convert(scene, out, config)`` in one process, the step
functions it chains (``steps``), and what the stage descriptors declare (``stages``).

Prefect tasks (``tasks/``) wrap the same step functions with caching and the content store; the flow
(``flows/convert_scene.py``) composes those tasks. Nothing here imports Prefect or model weights.
"""

from .convert import OUTPUT_KIND, ProgressFn, StageClock, convert, output_marker
from .stages import (STEPS, ConfigView, all_stages, closure, key_material, manifest_versions, step_config,
                     step_sections, view)
from .steps import (LoadedScene, articulate, assemble, check_physics, evaluate, export, finalize, load, openable_phrases,
                    pack_masks, perceive, record_physics, report, segment, split_on_oom)

__all__ = ["OUTPUT_KIND", "STEPS", "ConfigView", "LoadedScene", "ProgressFn", "StageClock", "all_stages", "articulate",
           "assemble", "check_physics", "closure", "convert", "evaluate", "export", "finalize", "key_material", "load",
           "manifest_versions", "openable_phrases", "output_marker", "pack_masks", "perceive", "record_physics", "report", "segment",
           "split_on_oom", "step_config", "step_sections", "view"]
