"""Assembly of the interactive scene: carving the background, labels and names."""

from pydantic import Field

from ._base import StageConfig


class AssemblyConfig(StageConfig):
    """Carving the background; the label rules of ``assembly.naming`` (rule 5: appliance doors)."""

    obb_margin_m: float = Field(0.005, ge=0, description="Grow part OBBs by this before deleting background vertices.")
    appliance_width_m: tuple[float, float] = Field(
        (0.4, 0.8), description="Width range (m) of an oven or dishwasher door: a front hinged at its bottom edge under a worktop, this wide, is an appliance door."
    )
    appliance_max_top_m: float = Field(
        1.0, gt=0, description="Highest top edge (m above the floor) of an oven or dishwasher door (under a worktop); a bottom-hinged front reaching higher is a flap."
    )
    dishwasher_max_bottom_m: float = Field(
        0.25, ge=0, description="A bottom-hinged appliance front whose bottom edge is within this (m) of the floor (on a plinth) and at least dishwasher_min_height_m tall is a dishwasher door."
    )
    dishwasher_min_height_m: float = Field(0.6, gt=0, description="Least height (m) of a dishwasher door; a shorter bottom-hinged appliance front is an oven door.")
    oven_min_height_m: float = Field(0.35, gt=0, description="A bottom-hinged front under a worktop lower than this (m) is a flap (a tilt-out sink front), not an oven door.")
