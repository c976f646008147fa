"""PhysX (the engine inside Isaac Sim) on the CPU through ``ovphysx``: optional, skipped when not installed.

ovphysx is large (~1 GB) and NVIDIA-licensed, so it is not a project dependency. To run this test:
    python3 -m venv --system-site-packages /tmp/ovphysx-venv
    /tmp/ovphysx-venv/bin/pip install ovphysx physx-usd-schemas newton-usd-schemas
    /tmp/ovphysx-venv/bin/python -m pytest tests/export/test_physx.py -q
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from react3d_core.data import InteractiveScene, load_mesh

ovphysx = pytest.importorskip("ovphysx")
ovstage = pytest.importorskip("ovstage")


@pytest.fixture(scope="module")
def physx_scene(exported: dict[str, Path]):  # noqa: ANN201
    from ovphysx import PhysX

    try:
        from ovphysx.samples.python_samples.schema_support import physx_schema_paths

        ovstage.population.register_usd_schemas([*[str(p) for p in physx_schema_paths()], str(ovphysx.newton_schema_root())])
    except (ImportError, FileNotFoundError) as exc:
        pytest.skip(f"PhysX USD schemas not installed: {exc}")
    PhysX.set_cpu_mode(True)
    physx = PhysX()
    stage = ovstage.Stage("react3d-export-test")
    ovstage.population.open_usd(stage, str(exported["usd"]), ordinal=1, domains=ovstage.PopulationDomain.ALL)
    stage.advance_write_floor(ordinal=1).wait()
    physx.wait_task(physx.attach_ovstage(stage, read_ordinal=1))
    physx.wait_all()
    yield physx
    physx.wait_task(physx.detach_ovstage())
    stage.destroy()
    physx.destroy()


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
        pose = _read(physx_scene, f"/World/{obj.object_id}/part", TensorType.RIGID_BODY_POSE).reshape(-1)
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
        pose = _read(physx_scene, f"{pat}/part", TensorType.RIGID_BODY_POSE).reshape(-1)
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat(pose[3:7]).as_matrix()
        T[:3, 3] = pose[:3]
        pts = load_mesh(root / obj.part_mesh).vertices
        got = (pts - np.asarray(art.origin)) @ T[:3, :3].T + T[:3, 3]
        assert np.linalg.norm(got - art.move(pts, q), axis=1).max() <= 5e-3
        _write(physx_scene, pat, TensorType.ARTICULATION_DOF_ACTUATION_FORCE, np.array([0.0]))
