"""``export_scene``: one manifest in, URDF / USD / MJCF folders out (each written atomically)."""

from __future__ import annotations

from pathlib import Path

from ..atomic import atomic_dir
from ..config.export import ExportConfig
from ..data.parts import InteractiveScene
from ..errors import InputError
from .assets import write_link_assets
from .model import SceneModel, build_scene_model

FORMATS = ("urdf", "usd", "mjcf")
FILES = {"urdf": "urdf/scene.urdf", "usd": "usd/scene.usda", "mjcf": "mjcf/scene.xml"}


def _write_urdf(model: SceneModel, folder: Path, config: ExportConfig) -> None:
    from .urdf import write_ros_package, write_urdf

    files = write_link_assets(model, folder, glb=config.write_glb)
    urdf = write_urdf(model, files, folder, config)
    if config.ros_launch:
        from ..report.ros_launch import write_ros_launch

        write_ros_launch(urdf)
    if config.ros_package:
        pkg = folder / "ros" / f"{model.scene_id.lower()}_description"
        write_link_assets(model, pkg, glb=False)
        write_ros_package(model, files, pkg, config)


def _write_mjcf(model: SceneModel, folder: Path, config: ExportConfig) -> None:
    from .mjcf import write_mjcf

    files = write_link_assets(model, folder, glb=False, collisions=False)
    write_mjcf(model, files, folder, config)


def _write_usd(model: SceneModel, folder: Path, config: ExportConfig) -> None:
    from .usd import write_usd

    write_usd(model, folder / "scene.usda", config)


_WRITERS = {"urdf": _write_urdf, "usd": _write_usd, "mjcf": _write_mjcf}


def export_scene(manifest_path: str | Path, formats: tuple[str, ...] | list[str] = FORMATS, config: ExportConfig | None = None) -> dict[str, Path]:
    """Export an InteractiveScene to simulator formats under ``<manifest dir>/export/<format>/``.

    Textures and collision pieces are computed once and shared by all formats. Each format folder
    is replaced atomically; the manifest's ``exports`` records the written files (relative paths).
    """
    config = config or ExportConfig()
    manifest_path = Path(manifest_path)
    if manifest_path.is_dir():
        manifest_path = manifest_path / "scene.json"
    bad = [f for f in formats if f not in _WRITERS]
    if bad or not formats:
        raise InputError(None, f"unknown export format(s) {bad or list(formats)}: choose from {', '.join(FORMATS)}")
    scene = InteractiveScene.load(manifest_path)
    root = manifest_path.parent
    model = build_scene_model(scene, root, config)
    out: dict[str, Path] = {}
    for fmt in dict.fromkeys(formats):
        target = root / "export" / fmt
        with atomic_dir(target) as tmp:
            _WRITERS[fmt](model, tmp, config)
        out[fmt] = root / "export" / FILES[fmt]
    exports = dict(scene.exports)
    exports.update({fmt: (Path("export") / FILES[fmt]).as_posix() for fmt in out})
    scene.model_copy(update={"exports": exports}).save(manifest_path)
    return out
