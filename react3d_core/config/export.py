"""Export: textures, collisions, inertia, formats."""

from pydantic import Field

from ._base import StageConfig


class ExportConfig(StageConfig):
    """What the exporters write."""

    formats: tuple[str, ...] = Field(("urdf", "usd", "mjcf"), description="Formats written by convert/export.")
    texel_per_m: float = Field(400.0, gt=0, description="Texture budget: texels per metre of surface (side length).")
    min_texture: int = Field(64, ge=8, description="Smallest texture side (px).")
    max_texture: int = Field(4096, ge=64, description="Largest texture side (px).")
    density_kg_m3: float = Field(500.0, gt=0, description="Density for inertials (wood-like).")
    min_mass_kg: float = Field(0.1, gt=0, description="Sane minimum mass.")
    max_convex_hulls: int = Field(16, ge=1, description="Convex pieces per movable body.")
    joint_effort: float = Field(50.0, gt=0, description="URDF effort limit.")
    joint_velocity: float = Field(1.0, gt=0, description="URDF velocity limit.")
    joint_damping: float = Field(1.0, ge=0, description="Joint damping.")
    ros_package: bool = Field(False, description="Also write a ROS 2 description package with package:// paths.")
    xatlas_max_faces: int = Field(
        20000, ge=1, description="Meshes up to this many faces get xatlas charts; larger ones the per-triangle cell atlas (xatlas ~3 s/20k faces, crashed at 80k)."
    )
    min_collision_thickness: float = Field(0.005, gt=0, description="Convex pieces thinner than this (m) become boxes this thick (flat scans have no volume).")
    background_patch_m: float = Field(0.5, gt=0, description="MJCF background collision: grid cell (m) of the planar convex patches.")
    ros_launch: bool = Field(True, description="Write RViz launch files beside the URDF.")
    write_glb: bool = Field(True, description="Also write a GLB per link (viewers; simulators read the OBJ).")
