"""Export stage: an InteractiveScene as URDF (PyBullet/ROS/Isaac importer), USD (PhysX) and MJCF (MuJoCo).

``export_scene(manifest, formats, config)`` writes ``<out>/export/{assets,urdf,usd,mjcf}`` (meshes and
textures once in ``assets``, referenced by every format);
``import_urdf(path)`` reads the articulations back for round trips.
"""

from ..stage import StageSpec
from .importer import import_urdf
from .scene import FORMATS, export_scene

STAGE_VERSION = "6"  # 2: one shared asset folder, binary USD, export_sizes; 3: colliders kept clear at rest and of every part's path, collision policy stated per format; 4: joint damping capped by what the joint moves, interleaved carcass walls moved to the territory plane; 5: deep walls are cut, not shifted, by a territory plane at an angle; side-by-side fronts with one flipped normal split across the row; 6: convex collision files centred on their own box centre (PhysX precision)
STAGE = StageSpec("export", __name__, STAGE_VERSION, sections=("export",), upstream=("assembly", "texture"))

__all__ = ["STAGE", "FORMATS", "STAGE_VERSION", "export_scene", "import_urdf"]
