"""A ``scene-synthesizer`` procedural kitchen (real cabinets, appliances, 20-30 joints) as a scan.

The kitchen is exported to URDF in a temporary folder and read back by :mod:`.from_urdf`, so both
sources share one code path; dishwasher baskets (internal sliding parts, not fronts) are skipped.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from .procedural import SynthLayout


def build_scene_synthesizer(seed: int = 0, edge: float = 0.03) -> SynthLayout:
    """Build ``scene_synthesizer.procedural_scenes.kitchen(seed)`` closed, as a :class:`SynthLayout`."""
    from scene_synthesizer import procedural_scenes

    from .from_urdf import build_from_urdf

    scene = procedural_scenes.kitchen(seed=seed)
    scene.zero_configurations()
    with tempfile.TemporaryDirectory(prefix="react3d-ss-") as d:
        urdf = Path(d) / "kitchen.urdf"
        scene.export(str(urdf))
        layout = build_from_urdf(urdf, seed=seed, edge=edge, kind="scene-synthesizer-kitchen")
    return layout
