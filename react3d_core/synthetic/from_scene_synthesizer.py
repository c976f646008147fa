"""A ``scene-synthesizer`` procedural kitchen (real cabinets, appliances, 20-30 joints) as a scan.

The kitchen is exported to URDF in a temporary folder and read back by :mod:`.from_urdf`, so both
sources share one code path; dishwasher baskets (internal sliding parts, not fronts) are skipped.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .procedural import SynthLayout


def build_scene_synthesizer(seed: int = 0, edge: float = 0.03) -> SynthLayout:
    """Build ``scene_synthesizer.procedural_scenes.kitchen(seed)`` closed, as a :class:`SynthLayout`."""
    from scene_synthesizer import procedural_scenes

    from .from_urdf import build_from_urdf

    with tempfile.TemporaryDirectory(prefix="react3d-ss-") as d, _asset_files_in(d):
        scene = procedural_scenes.kitchen(seed=seed)
        scene.zero_configurations()
        urdf = Path(d) / "kitchen.urdf"
        scene.export(str(urdf))
        layout = build_from_urdf(urdf, seed=seed, edge=edge, kind="scene-synthesizer-kitchen")
    return layout


@contextmanager
def _asset_files_in(folder: str) -> Iterator[None]:
    """scene-synthesizer writes every procedural door, handle and sink mesh to a random file in a
    hard-coded ``/tmp`` and never removes it (about 60 files per kitchen, thousands over a dataset).
    While a kitchen is built, its files go to ``folder`` instead, which is removed with the build."""
    from scene_synthesizer import utils

    real = utils.get_random_filename

    def into_folder(suffix: str, prefix: str = "", dir: str = "/tmp") -> str:  # noqa: A002 - the library's name
        return real(suffix, prefix=prefix, dir=folder if dir == "/tmp" else dir)

    utils.get_random_filename = into_folder
    try:
        yield
    finally:
        utils.get_random_filename = real
