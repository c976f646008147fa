"""Assembly of the interactive scene: carving the background."""

from pydantic import Field

from ._base import StageConfig


class AssemblyConfig(StageConfig):
    """Carving the background."""

    obb_margin_m: float = Field(0.005, ge=0, description="Grow part OBBs by this before deleting background vertices.")
