"""The method as plain functions, one per step, over loaded objects (no Prefect, no store, no weights).

``tasks/`` wraps each in a cached Prefect task that moves handles into and out of the content store;
:func:`react3d_core.pipeline.convert` chains them in-process. Both therefore compute the same thing.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from ..config import EvaluationConfig, ExportConfig, FrameSelectionConfig, PerceptionConfig, PhysicsConfig, PipelineConfig
from ..data.frames import Frame, SceneInput
from ..data.masks import ArticulationPrediction, Mask2D, PackedMasks
from ..data.mesh import TriMesh, load_mesh
from ..data.parts import InteractiveScene, PartCandidate
from ..perception.interfaces import Perception, PointPromptSegmenter
from ..raster import Rasterizer
from ..scene_io.selection import SelectionMemo
from .stages import view

T = TypeVar("T")


@dataclass
class LoadedScene:
    """A scan with its selected frames and one rasterizer (holding the mesh) shared by every stage."""

    scene: SceneInput
    raster: Rasterizer

    @property
    def mesh(self) -> TriMesh:
        return self.raster.mesh


def load(scene_path: str | Path, frames: FrameSelectionConfig,
         raster_for: Callable[[str | Path], Rasterizer] | None = None, memo: SelectionMemo | None = None,
         cache_dir: str | Path | None = None) -> LoadedScene:
    """Load and validate the scan (units included) and select its frames (keyframes by default).

    ``raster_for(mesh_path)``: where the scan's rasterizer comes from (a worker keeps one per mesh);
    by default it is built here, once. ``memo``: remembered keyframe selections (``SelectionMemo``).
    With ``frames.missed_surface.enabled`` the scan is completed with slabs over the surfaces the depth
    sensor missed, kept under ``cache_dir`` (default ``$REACT3D_CACHE``), and every stage reads that mesh."""
    from ..scene_io import load_scene
    from ..scene_io.scale import check_scale

    if raster_for is None:
        built: dict[str, Rasterizer] = {}

        def raster_for(mesh_path: str | Path) -> Rasterizer:
            if str(mesh_path) not in built:
                built[str(mesh_path)] = Rasterizer(load_mesh(mesh_path))
            return built[str(mesh_path)]

    scene = load_scene(scene_path, frames, rasterizer=raster_for, memo=memo)
    raster = raster_for(scene.mesh_path)
    check_scale(scene, raster.mesh)  # a millimetre mesh otherwise gives 0 parts, rc 0
    if frames.missed_surface.enabled:
        import os

        from ..scene_io.missed_surface import complete_scene

        root = cache_dir or os.environ.get("REACT3D_CACHE", Path.home() / ".cache" / "react3d")
        scene = complete_scene(scene, raster, frames.missed_surface, root)
        raster = raster_for(scene.mesh_path)
    return LoadedScene(scene, raster)


def openable_phrases(kept: Sequence[str], cfg: PerceptionConfig) -> list[str]:
    """Text prompts for the segmenter: each kept tag as '<tag> door' (paper), 'door' itself as is."""
    out = []
    for t in sorted(set(kept) | set(cfg.always_keep_tags)):
        out.append(t if t.endswith("door") or t in cfg.always_keep_tags else t + cfg.prompt_suffix)
    return out


def _is_oom(exc: BaseException) -> bool:
    return "OutOfMemory" in type(exc).__name__ or "out of memory" in str(exc).lower()


def split_on_oom(fn: Callable[[list[Any], list[Any]], list[T]], frames: list[Any], images: list[Any]) -> list[T]:
    """Call ``fn`` on the batch; on a GPU out-of-memory error, call it on each half (down to single frames)."""
    try:
        return fn(frames, images)
    except Exception as exc:  # noqa: BLE001 - only OOM is handled, everything else re-raised
        if not _is_oom(exc) or len(frames) == 1:
            raise
    # Outside the except block: the failed attempt's traceback (and the GPU tensors its frames hold) is
    # gone before the halves run, and the allocator's cached blocks are returned.
    _release_gpu_cache()
    h = len(frames) // 2
    return split_on_oom(fn, frames[:h], images[:h]) + split_on_oom(fn, frames[h:], images[h:])


def _release_gpu_cache() -> None:
    """torch.cuda.empty_cache() when torch is loaded (the core itself never imports it)."""
    torch = sys.modules.get("torch")
    if torch is not None and torch.cuda.is_available():
        torch.cuda.empty_cache()


def perceive(perception: Perception, frames: Sequence[Frame], cfg: PerceptionConfig) -> dict[str, Any]:
    """Tags -> openable phrases -> 2D masks, and articulation predictions, for a batch of frames:
    ``{"masks": {frame_id: [Mask2D]}, "predictions": {...}, "tags": {...}, "phrases": [...]}``."""
    from ..scene_io.images import frame_rgb

    frames = list(frames)
    images = [frame_rgb(f) for f in frames]
    ids = [f.frame_id for f in frames]
    tags = split_on_oom(lambda fr, im: perception.tagger.tag(fr, im), frames, images)
    all_tags = sorted({t for ts in tags for t in ts})
    kept = perception.tag_filter.filter(all_tags) if all_tags else []
    phrases = openable_phrases(kept, cfg)
    masks = split_on_oom(lambda fr, im: perception.segmenter.segment(fr, im, phrases), frames, images)
    preds = split_on_oom(lambda fr, im: perception.articulation.predict(fr, im), frames, images)
    return {"masks": {fid: list(m) for fid, m in zip(ids, masks)},
            "predictions": {fid: list(p) for fid, p in zip(ids, preds)},
            "tags": {fid: list(t) for fid, t in zip(ids, tags)},
            "phrases": phrases}


def pack_masks(batches: Iterable[Mapping[str, Sequence[Mask2D]]]) -> PackedMasks:
    """Every frame's masks, bit-packed (a long capture's masks stay small)."""
    masks = PackedMasks()
    for batch in batches:
        for fid, ms in batch.items():
            masks.add(fid, ms)
    return masks


def segment(loaded: LoadedScene, masks: PackedMasks, point_segmenter: PointPromptSegmenter,
            config: PipelineConfig | dict[str, Any]) -> list[PartCandidate]:
    """Fuse every frame's masks into 3D part candidates with their top-k views."""
    from ..fusion import segment_parts

    return list(segment_parts(loaded.scene, loaded.mesh, masks, point_segmenter, view(config, "segmentation"),
                              rasterizer=loaded.raster))


def candidate_views(candidate: PartCandidate) -> set[str]:
    """Frames whose predictions a candidate's articulation reads (its top views)."""
    return {v.frame_id for v in candidate.top_views}


def articulate(loaded: LoadedScene, candidate: PartCandidate,
               predictions: Mapping[str, list[ArticulationPrediction]], config: PipelineConfig | dict[str, Any]) -> Any:
    """Validate a candidate against the articulation predictor and refine its joint (None: rejected)."""
    from ..articulation import articulate_candidate

    views = candidate_views(candidate)
    preds = {fid: p for fid, p in predictions.items() if fid in views}
    return articulate_candidate(loaded.scene, loaded.mesh, candidate, preds, view(config, "articulation"),
                                rasterizer=loaded.raster)


def assemble(loaded: LoadedScene, parts: Sequence[Any], config: PipelineConfig | dict[str, Any],
             out_dir: str | Path) -> InteractiveScene:
    """Deduplicate, add cavities and limits, carve the background; writes the scene into ``out_dir``."""
    from ..assembly import assemble_scene

    return assemble_scene(loaded.scene, loaded.mesh, [p for p in parts if p is not None], view(config, "assembly"),
                          out_dir)


def export(manifest_path: str | Path, formats: Sequence[str], cfg: ExportConfig) -> dict[str, Path]:
    """URDF / USD / MJCF (shared asset folder, textures, collisions) beside the manifest."""
    from ..export import export_scene

    return export_scene(manifest_path, tuple(formats), cfg)


def check_physics(out_dir: str | Path, cfg: PhysicsConfig) -> dict[str, Any]:
    """The physics check of an exported scene (``react3d_core.physics``), as a JSON dict."""
    from ..physics import check_output

    return check_output(out_dir, cfg).model_dump(mode="json")


def record_physics(manifest_path: str | Path, check: dict[str, Any] | None, error: str | None = None) -> None:
    """Write the full check beside the manifest (``physics_check.json``) and its summary into the manifest's
    ``physics`` key; ``error``: the check itself could not run (the conversion still succeeds)."""
    from ..atomic import write_json
    from ..physics import DEFAULT_JSON, PhysicsCheck

    manifest_path = Path(manifest_path)
    if check is not None:
        write_json(manifest_path.parent / DEFAULT_JSON, check)
        summary = {**PhysicsCheck.model_validate(check).summary(), "file": DEFAULT_JSON}
    else:
        summary = {"passed": False, "error": error or "not run"}
    m = InteractiveScene.load(manifest_path)
    m.model_copy(update={"physics": summary}).save(manifest_path)


def evaluate(manifest_path: str | Path, gt_dir: str | Path, cfg: EvaluationConfig) -> dict[str, Any]:
    """The paper's metrics against the scene's ground truth; also written to ``metrics.json``."""
    from ..atomic import write_json
    from ..ground_truth import read_articulate3d
    from ..metrics import evaluate_scene, to_json_dict

    pred = InteractiveScene.load(manifest_path)
    metrics = evaluate_scene(pred, Path(manifest_path).parent, read_articulate3d(gt_dir), cfg)
    out = to_json_dict([metrics])
    write_json(Path(manifest_path).parent / "metrics.json", out)
    return out


def report(manifest_path: str | Path, scene: SceneInput | None, metrics: dict[str, Any] | None,
           cache_dir: str | Path | None = None) -> Path:
    """``report.html`` beside the manifest: the viewer with a slider per joint, thumbnails, metrics."""
    from ..viewer import write_report

    per_tau = metrics.get("aggregate", metrics) if metrics else None
    return Path(write_report(manifest_path, scene_input=scene, metrics=per_tau, cache_dir=cache_dir))


def finalize(manifest_path: str | Path, config: dict[str, Any], versions: dict[str, str],
             timings: dict[str, float]) -> None:
    """Record the config, stage versions and timings of the run in its manifest."""
    m = InteractiveScene.load(manifest_path)
    m.model_copy(update={"config": config, "versions": {**m.versions, **versions},
                         "timings": {**m.timings, **timings}}).save(manifest_path)

