"""Which frames of a capture are used."""

from pydantic import Field

from ._base import StageConfig


class FrameSelectionConfig(StageConfig):
    """Frame selection. Default (``stride`` None): keyframes by what the views add — camera motion since
    the last kept frame, then new or under-observed surface in a low-resolution face-id buffer — capped
    at ``keyframe_cap``. A fixed stride suits one frame rate only (stride 5 kept 12 of a sparse
    60-frame capture); an explicit ``stride`` is still honoured as given."""

    stride: int | None = Field(None, ge=1, description="Use every n-th frame; None selects keyframes by motion and coverage.")
    max_frames: int | None = Field(None, ge=1, description="Explicit cap on the number of frames (evenly subsampled), any mode.")
    keyframes: bool = Field(False, description="With an explicit stride: also keep a frame only when the camera moved/turned enough since the last kept one.")
    keyframe_translation_m: float = Field(0.05, gt=0, description="Keyframe: minimum camera translation since the last kept frame (m).")
    keyframe_rotation_deg: float = Field(3.0, gt=0, description="Keyframe: minimum camera rotation since the last kept frame (deg).")
    keyframe_cap: int = Field(300, ge=1, description="Keyframe mode: at most this many frames (evenly subsampled from the keyframes).")
    coverage_width: int = Field(64, ge=0, description="Keyframe mode: width (px) of the face-id buffer used to measure what a view adds; 0 = motion only.")
    coverage_target_views: int = Field(10, ge=1, description="Keyframe mode: surface seen in this many kept frames counts as covered.")
    coverage_voxel_m: float = Field(0.05, gt=0, description="Keyframe mode: surface is counted per voxel of this side (m) when measuring what a view adds (about one coverage-buffer pixel at 2 m).")
    coverage_min_new: float = Field(0.05, ge=0, le=1, description="Keyframe mode: keep a moved frame only if at least this fraction of its surface pixels is not yet covered.")
    image_width: int = Field(960, ge=32, description="RGB working width; the reference worked at 960x720. K is rescaled with it.")
