"""Scene assembly: dedup -> cavity -> limits -> carving -> meshes + ``scene.json``.

The stage lives in :mod:`.scene`; this package names it and its version."""

from ..stage import StageSpec
from .scene import assemble_scene, attached_faces, carve_background, sliding_limits

STAGE_VERSION = "5"  # 3: sliding doors: travel along their width, no drawer box; 4: limits from physics (drawer travel within the body, conservative sweeps of part and handle, prismatic sweep, blocked parts); 5: labels and names from the evidence (drawer_03)
STAGE = StageSpec("assembly", __name__, STAGE_VERSION, sections=("assembly", "limits"), upstream=("dedup", "cavity"))

__all__ = ["STAGE", "STAGE_VERSION", "assemble_scene", "attached_faces", "carve_background", "sliding_limits"]
