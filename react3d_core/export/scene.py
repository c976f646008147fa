"""``export_scene``: one manifest in, one ``export/`` folder out (shared assets + URDF / USD / MJCF).

Layout (written atomically as a whole, so formats never point at assets of another export)::

    export/assets/<link>/visual_<k>/{mesh.obj, material.mtl, material_0.png}   written once
    export/assets/<link>/collision_<k>.obj, patches/patch_<k>.obj              (URDF colliders)
    export/urdf/scene.urdf   -> ../assets/...
    export/mjcf/scene.xml    -> ../assets/...
    export/usd/scene.usda (small root) + scene.usdc (binary stage) -> ../assets/... textures
"""

from __future__ import annotations

import os
from pathlib import Path

from ..atomic import atomic_dir
from ..config.export import FORMATS, ExportConfig
from ..data.parts import InteractiveScene
from ..errors import InputError
from .assets import ASSETS, LinkFiles, write_link_assets
from .model import SceneModel, build_scene_model

FILES = {"urdf": "urdf/scene.urdf", "usd": "usd/scene.usda", "mjcf": "mjcf/scene.xml"}


def entry_file(fmt: str, config: ExportConfig) -> str:
    """The file a simulator opens for ``fmt``, relative to ``export/``."""
    if fmt == "usd" and config.usd_binary and not config.usd_ascii_root:
        return "usd/scene.usdc"
    return FILES[fmt]


def _write_urdf(model: SceneModel, folder: Path, files: dict[str, LinkFiles], config: ExportConfig) -> None:
    from .urdf import write_ros_package, write_urdf

    urdf = write_urdf(model, files, folder, config)
    if config.ros_launch:
        from .ros_launch import write_ros_launch

        write_ros_launch(urdf)
    if config.ros_package:  # a ROS package must be self-contained: its own copy of the meshes
        pkg = folder / "ros" / f"{model.scene_id.lower()}_description"
        pkg_files = write_link_assets(model, pkg, config, glb=False, subdir="meshes")
        write_ros_package(model, pkg_files, pkg, config)


def _write_mjcf(model: SceneModel, folder: Path, files: dict[str, LinkFiles], config: ExportConfig) -> None:
    from .mjcf import write_mjcf

    write_mjcf(model, files, folder, config)


def _write_usd(model: SceneModel, folder: Path, files: dict[str, LinkFiles], config: ExportConfig) -> None:
    from .usd import write_usd

    write_usd(model, folder / Path(entry_file("usd", config)).name, config, files)


_WRITERS = {"urdf": _write_urdf, "usd": _write_usd, "mjcf": _write_mjcf}


def folder_bytes(folder: Path) -> int:
    """Total size of the files under ``folder`` (0 if absent)."""
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file()) if folder.is_dir() else 0


def size_report(export_dir: Path, formats: list[str]) -> dict[str, int]:
    """Bytes on disk: the shared assets, each format's own files, and the total (``export/``)."""
    out = {"assets": folder_bytes(export_dir / ASSETS)}
    out.update({fmt: folder_bytes(export_dir / fmt) for fmt in formats})
    out["total"] = folder_bytes(export_dir)
    return out


def export_scene(manifest_path: str | Path, formats: tuple[str, ...] | list[str] = FORMATS, config: ExportConfig | None = None,
                 cache_dir: str | Path | None = None) -> dict[str, Path]:
    """Export an InteractiveScene to simulator formats under ``<manifest dir>/export/``.

    Textures and collision pieces are computed once, written once into ``export/assets`` and
    referenced by every format. ``export/`` is replaced atomically and holds exactly ``formats``;
    the manifest's ``exports`` records the entry files (relative paths) and ``export_sizes`` the
    bytes per part. ``cache_dir``: where convex decompositions are cached by mesh content (default
    ``$REACT3D_CACHE/collisions`` when ``config.collision_cache``).
    """
    config = config or ExportConfig()
    manifest_path = Path(manifest_path)
    if manifest_path.is_dir():
        manifest_path = manifest_path / "scene.json"
    bad = [f for f in formats if f not in _WRITERS]
    if bad or not formats:
        raise InputError(None, f"unknown export format(s) {bad or list(formats)}: choose from {', '.join(FORMATS)}")
    formats = list(dict.fromkeys(formats))
    scene = InteractiveScene.load(manifest_path)
    root = manifest_path.parent
    if cache_dir is None and config.collision_cache:
        cache_dir = Path(os.environ.get("REACT3D_CACHE", Path.home() / ".cache" / "react3d")) / "collisions"
    model = build_scene_model(scene, root, config, cache_dir=cache_dir)
    target = root / "export"
    with atomic_dir(target) as tmp:
        files = write_link_assets(model, tmp, config, collisions="urdf" in formats,
                                  png_for_mjcf="mjcf" in formats and config.texture_format != "png")
        seen_from_format = {name: f.prefixed("../") for name, f in files.items()}
        for fmt in formats:
            (tmp / fmt).mkdir()
            _WRITERS[fmt](model, tmp / fmt, seen_from_format, config)
        sizes = size_report(tmp, formats)
    out = {fmt: target / entry_file(fmt, config) for fmt in formats}
    exports = {fmt: (Path("export") / entry_file(fmt, config)).as_posix() for fmt in formats}
    # a new export invalidates an earlier physics check of the old one
    scene.model_copy(update={"exports": exports, "export_sizes": sizes, "physics": None}).save(manifest_path)
    return out
