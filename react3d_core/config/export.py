"""Export: textures, collisions, inertia, formats."""

from typing import Literal

from pydantic import Field

from ._base import StageConfig

FORMATS = ("urdf", "usd", "mjcf")
"""Simulator formats the exporters write (here, not in react3d_core.export: checking a command line's
formats must not import the exporters, 1.8 s of a cached convert's start-up)."""


class ExportConfig(StageConfig):
    """What the exporters write."""

    formats: tuple[str, ...] = Field(FORMATS, description="Formats written by convert/export.")
    texel_per_m: float = Field(400.0, gt=0, description="Texture budget: texels per metre of surface (side length).")
    min_texture: int = Field(64, ge=8, description="Smallest texture side (px).")
    max_texture: int = Field(4096, ge=64, description="Largest texture side (px).")
    density_kg_m3: float = Field(500.0, gt=0, description="Density for inertials (wood-like).")
    min_mass_kg: float = Field(0.1, gt=0, description="Sane minimum mass.")
    max_convex_hulls: int = Field(16, ge=1, description="Convex pieces per movable body.")
    joint_effort: float = Field(50.0, gt=0, description="URDF effort limit.")
    joint_velocity: float = Field(1.0, gt=0, description="URDF velocity limit.")
    joint_damping: float = Field(1.0, ge=0, description="Joint damping (N s/m or N m s/rad), capped per joint by joint_damping_max_rate.")
    joint_damping_max_rate: float = Field(
        10.0, gt=0,
        description="A joint's damping is at most this many times what it moves (its mass, or its moment about the hinge), "
                    "in 1/s: a light part keeps a drive able to move it and an explicit integrator stable.")
    ros_package: bool = Field(False, description="Also write a ROS 2 description package with package:// paths.")
    xatlas_max_faces: int = Field(
        2000, ge=1,
        description="Meshes up to this many faces get xatlas charts (fewer seams); larger ones the per-triangle cell atlas "
        "(exact at vertices, 3 UVs per face). Was 20000: xatlas took 1.3 s per 10k-face scanned part unloaded and 6-37 s "
        "under load, the cell atlas 0.01-0.06 s for the same parts with a same-sized texture; xatlas crashed at 80k.",
    )
    min_collision_thickness: float = Field(0.005, gt=0, description="Convex pieces thinner than this (m) become boxes this thick (flat scans have no volume).")
    background_patch_m: float = Field(0.5, gt=0, description="MJCF/URDF background collision: grid cell (m) of the planar convex patches.")
    background_patch_min_m: float = Field(
        0.03, gt=0,
        description="Smallest patch cell (m): a patch near a part's path or a carcass, or spanning several parallel surfaces, is refitted "
        "in cells half as large down to this, so the background hugs the gaps around fronts instead of bridging them.",
    )
    background_slab_m: float = Field(
        0.02, gt=0,
        description="MJCF/URDF background patches are slabs this thick (m) behind their surface: a slab cut back near a part (the floor under "
        "a door's swing) still leaves a surface, and a fast body does not tunnel through a wall.",
    )
    background_patch_flatness_m: float = Field(
        0.02, gt=0, description="A background patch whose faces lie further apart than this (m) along its normal (a front and the wall behind it) is split.",
    )
    collider_clearance_m: float = Field(
        0.005, ge=0,
        description="Gap (m) kept between colliders at rest and around every part's swept volume: background patches and triangles, "
        "carcasses and overlapping part hulls are cut back so that nothing static stands in a part's path and no pair starts in contact "
        "(overlaps at rest gave hundreds of contacts and jammed joints in every engine).",
    )
    part_trim_max_fraction: float = Field(
        0.3, ge=0, le=1,
        description="Where a part's path meets another part at rest (a drawer's box passing its neighbour's edge, a door's back edge "
        "swinging past the next door), the piece that loses less volume is cut, if that is at most this fraction of it. Deeper "
        "conflicts are left for the joint limits to settle.",
    )
    ros_launch: bool = Field(True, description="Write RViz launch files beside the URDF.")
    write_glb: bool = Field(
        False, description="Also write a GLB per link into the shared assets (viewers only: no simulator reads it; it re-embeds geometry and texture, 41 MB on a 490k-face scan)."
    )
    texture_format: Literal["png", "jpg"] = Field(
        "png",
        description="Baked texture files. PNG is lossless and the only format all three simulators read (MuJoCo 4 reads PNG, not JPEG); "
        "JPEG is ~4x smaller on a scan texture but blurs the per-triangle cell atlas, and MJCF then gets a PNG copy beside it.",
    )
    png_compression: int = Field(3, ge=0, le=9, description="zlib level of PNG textures (measured on a 2430^2 scan texture: 3 -> 7.4 MB in 0.5 s, 9 -> 6.8 MB in 7.9 s).")
    jpeg_quality: int = Field(90, ge=1, le=100, description="JPEG quality when texture_format is jpg.")
    usd_binary: bool = Field(True, description="Write the USD stage as binary crate (scene.usdc): ~4x smaller and faster to open than ASCII .usda.")
    usd_ascii_root: bool = Field(True, description="With usd_binary, also write a small scene.usda root that sublayers scene.usdc (readable stage metadata).")
    collision_cache: bool = Field(True, description="Cache convex decompositions and background patches by mesh content (REACT3D_CACHE/collisions), so a re-export reuses them.")
