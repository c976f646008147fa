"""Export stage: an InteractiveScene as URDF (PyBullet/ROS/Isaac importer), USD (PhysX) and MJCF (MuJoCo).

``export_scene(manifest, formats, config)`` writes ``<out>/export/{urdf,usd,mjcf}``;
``import_urdf(path)`` reads the articulations back for round trips.
"""

from .importer import import_urdf
from .scene import FORMATS, export_scene

STAGE_VERSION = "1"

__all__ = ["FORMATS", "STAGE_VERSION", "export_scene", "import_urdf"]
