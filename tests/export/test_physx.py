"""PhysX (the engine inside Isaac Sim) on the CPU through ``ovphysx``: optional, skipped when not installed.

ovphysx is large (~1 GB) and NVIDIA-licensed, so it is not a project dependency. Isaac Sim's URDF
importer (``urdf-usd-converter``) ships its own OpenUSD and conflicts with usd-core, so it lives in a
separate venv and runs as a subprocess. To run these tests:
    python3 -m venv --system-site-packages /tmp/ovphysx-venv
    /tmp/ovphysx-venv/bin/pip install ovphysx physx-usd-schemas newton-usd-schemas
    python3 -m venv /tmp/urdfconv-venv && /tmp/urdfconv-venv/bin/pip install urdf-usd-converter
    REACT3D_URDF_USD_CONVERTER=/tmp/urdfconv-venv/bin/urdf_usd_converter \
        /tmp/ovphysx-venv/bin/python -m pytest tests/export/test_physx.py -q
"""

from __future__ import annotations

from pathlib import Path

import contextlib
import os
import shutil
import subprocess
from collections.abc import Iterator

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from react3d_core.data import InteractiveScene, load_mesh

ovphysx = pytest.importorskip("ovphysx")
ovstage = pytest.importorskip("ovstage")


_SCHEMAS: list[bool] = []


@contextlib.contextmanager
def physx_stage(usd_path: Path) -> Iterator[object]:
    """A CPU PhysX instance with ``usd_path`` attached (schemas registered once per process)."""
    from ovphysx import PhysX

    if not _SCHEMAS:
        try:
            from ovphysx.samples.python_samples.schema_support import physx_schema_paths

            ovstage.population.register_usd_schemas([*[str(p) for p in physx_schema_paths()], str(ovphysx.newton_schema_root())])
        except (ImportError, FileNotFoundError) as exc:
            pytest.skip(f"PhysX USD schemas not installed: {exc}")
        PhysX.set_cpu_mode(True)  # process-global, allowed once before the first instance
        _SCHEMAS.append(True)
    physx = PhysX()
    stage = ovstage.Stage(f"react3d-{usd_path.stem}")
    try:
        ovstage.population.open_usd(stage, str(usd_path), ordinal=1, domains=ovstage.PopulationDomain.ALL)
        stage.advance_write_floor(ordinal=1).wait()
        physx.wait_task(physx.attach_ovstage(stage, read_ordinal=1))
        physx.wait_all()
        yield physx
        physx.wait_task(physx.detach_ovstage())
    finally:
        stage.destroy()
        physx.destroy()


@pytest.fixture(scope="module")
def physx_scene(exported: dict[str, Path]):  # noqa: ANN201
    with physx_stage(exported["usd"]) as physx:
        yield physx


def _read(physx, pattern: str, kind) -> np.ndarray:  # noqa: ANN001
    b = physx.create_tensor_binding(pattern=pattern, tensor_type=kind)
    try:
        out = np.zeros(b.shape, np.float32)
        b.read(out)
        return out
    finally:
        b.destroy()


def _write(physx, pattern: str, kind, values: np.ndarray) -> None:  # noqa: ANN001
    b = physx.create_tensor_binding(pattern=pattern, tensor_type=kind)
    try:
        b.write(np.ascontiguousarray(values, np.float32).reshape(b.shape))
    finally:
        b.destroy()


def test_physx_loads_one_articulation_per_object_with_limits(physx_scene, exported: dict[str, Path]) -> None:  # noqa: ANN001
    from ovphysx.types import TensorType

    scene = InteractiveScene.load(exported["urdf"].parents[2] / "scene.json")
    for obj in scene.objects:
        roots = _read(physx_scene, f"/World/{obj.object_id}", TensorType.ARTICULATION_ROOT_POSE)
        assert roots.shape[0] == 1
        lim = _read(physx_scene, f"/World/{obj.object_id}", TensorType.ARTICULATION_DOF_LIMIT).reshape(-1)
        np.testing.assert_allclose(lim, [obj.articulation.lower, obj.articulation.upper], atol=1e-4)
        pose = _read(physx_scene, f"/World/{obj.object_id}/{obj.object_id}", TensorType.RIGID_BODY_POSE).reshape(-1)
        np.testing.assert_allclose(pose[:3], obj.articulation.origin, atol=1e-5)  # nothing moved at load


def test_physx_drives_each_joint_to_its_limit(physx_scene, exported: dict[str, Path]) -> None:  # noqa: ANN001
    from ovphysx.types import TensorType

    root = exported["urdf"].parents[2]
    scene = InteractiveScene.load(root / "scene.json")
    for obj in scene.objects:
        art = obj.articulation
        pat = f"/World/{obj.object_id}"
        _write(physx_scene, pat, TensorType.ARTICULATION_DOF_ACTUATION_FORCE, np.array([20.0]))
        for _ in range(240):  # 4 s at 60 Hz
            physx_scene.step(1 / 60)
            physx_scene.wait_all()
        q = float(_read(physx_scene, pat, TensorType.ARTICULATION_DOF_POSITION).reshape(-1)[0])
        assert q == pytest.approx(art.upper, abs=0.02 * max(art.upper, 1.0))  # pushed open, stopped at the limit
        pose = _read(physx_scene, f"{pat}/{obj.object_id}", TensorType.RIGID_BODY_POSE).reshape(-1)
        assert part_error(pose, load_mesh(root / obj.part_mesh).vertices, art, q) <= 5e-3
        _write(physx_scene, pat, TensorType.ARTICULATION_DOF_ACTUATION_FORCE, np.array([0.0]))


def part_error(pose: np.ndarray, pts: np.ndarray, art, q: float) -> float:  # noqa: ANN001
    """Max distance between the part placed by a PhysX body pose (x y z qx qy qz qw) and Articulation.move."""
    R = Rotation.from_quat(pose[3:7]).as_matrix()
    got = (pts - np.asarray(art.origin)) @ R.T + pose[:3]
    return float(np.linalg.norm(got - art.move(pts, q), axis=1).max())


def test_isaac_urdf_importer_output_loads_in_physx_with_same_joints(exported: dict[str, Path], tmp_path: Path) -> None:
    """Isaac Sim's URDF importer converts our URDF; PhysX loads it with our joint table and motion."""
    from ovphysx.types import TensorType
    from pxr import Usd, UsdPhysics

    exe = os.environ.get("REACT3D_URDF_USD_CONVERTER") or shutil.which("urdf_usd_converter")
    if not exe:
        pytest.skip("urdf-usd-converter not installed (set REACT3D_URDF_USD_CONVERTER)")
    res = subprocess.run([exe, "--no-layer-structure", str(exported["urdf"]), str(tmp_path / "isaac")], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    usd = next((tmp_path / "isaac").glob("*.usd*"))
    stage = Usd.Stage.Open(str(usd))
    prims = {p.GetName(): str(p.GetPath()) for p in stage.Traverse()}
    roots = [str(p.GetPath()) for p in stage.Traverse() if p.HasAPI(UsdPhysics.ArticulationRootAPI)]
    assert len(roots) == 1  # the importer makes the whole URDF one fixed-base articulation
    root = exported["urdf"].parents[2]
    scene = InteractiveScene.load(root / "scene.json")
    with physx_stage(usd) as physx:
        lim = _read(physx, roots[0], TensorType.ARTICULATION_DOF_LIMIT).reshape(-1, 2)
        want = sorted((o.articulation.lower, o.articulation.upper) for o in scene.objects)
        np.testing.assert_allclose(sorted(map(tuple, lim)), want, atol=1e-4)
        _write(physx, roots[0], TensorType.ARTICULATION_DOF_ACTUATION_FORCE, np.full(len(lim), 20.0))
        for _ in range(240):
            physx.step(1 / 60)
            physx.wait_all()
        for obj in scene.objects:
            pose = _read(physx, prims[obj.object_id], TensorType.RIGID_BODY_POSE).reshape(-1)
            art = obj.articulation
            assert part_error(pose, load_mesh(root / obj.part_mesh).vertices, art, art.upper) <= 5e-3
