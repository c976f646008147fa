"""Physics check: the exported scene driven in MuJoCo, PyBullet and SAPIEN, with collisions and gravity.

Each joint alone is driven to its limit and back under a PD position controller; how far it got, how
deep it pressed into other bodies and what it touched are recorded, with instabilities; a probe sphere
is dropped into each open cavity (must fall in freely) and pushed against each closed front (must be
blocked). ``check_output(out)`` runs it on a conversion's output; simulators are imported only when
used, and a missing one is skipped with the reason. Definitions: docs/physics.md.
"""

from ..stage import StageSpec
from .check import DEFAULT_JSON, check_output, load_output, write_check
from .result import EngineCheck, JointCheck, PhysicsCheck, ProbeCheck, RestCheck, Touch

STAGE_VERSION = "1"
STAGE = StageSpec("physics", __name__, STAGE_VERSION, sections=("physics",), upstream=("export",))

__all__ = ["DEFAULT_JSON", "STAGE", "STAGE_VERSION", "EngineCheck", "JointCheck", "PhysicsCheck", "ProbeCheck", "RestCheck",
           "Touch", "check_output", "load_output", "write_check"]
