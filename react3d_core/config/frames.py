"""Which frames of a capture are used."""

from pydantic import Field

from ._base import StageConfig


class FrameSelectionConfig(StageConfig):
    """Frame selection: stride first, then keyframes by pose change, then a cap."""

    stride: int = Field(5, ge=1, description="Use every n-th frame (the reference used every 5th iPhone frame).")
    max_frames: int | None = Field(None, ge=1, description="Cap on the number of frames (evenly subsampled).")
    keyframes: bool = Field(False, description="Keep a frame only when the camera moved/turned enough since the last kept one.")
    keyframe_translation_m: float = Field(0.15, gt=0, description="Keyframe: minimum camera translation (m).")
    keyframe_rotation_deg: float = Field(10.0, gt=0, description="Keyframe: minimum camera rotation (deg).")
    image_width: int = Field(960, ge=32, description="RGB working width; the reference worked at 960x720. K is rescaled with it.")
