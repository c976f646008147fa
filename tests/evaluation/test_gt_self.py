"""GT scored against itself must be perfect; the CLI works on a GT-as-prediction folder."""

import json
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from flows.cli import main
from react3d_core.data.mesh import TriMesh, save_mesh
from react3d_core.data.parts import Articulation
from react3d_core.errors import InputError
from react3d_core.ground_truth.articulate3d import GroundTruth, GTPart, write_articulate3d
from react3d_core.metrics import gt_to_scene, run_evaluation


def _grid(n: int = 20) -> TriMesh:
    """n x n vertex grid in the x-z plane (a wall), two triangles per cell."""
    x, z = np.meshgrid(np.arange(n, dtype=float) * 0.05, np.arange(n, dtype=float) * 0.05, indexing="ij")
    v = np.stack([x.ravel(), np.zeros(n * n), z.ravel()], 1)
    i = np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]
    i = i.ravel()
    f = np.concatenate([np.stack([i, i + n, i + 1], 1), np.stack([i + 1, i + n, i + n + 1], 1)])
    return TriMesh(v, f)


def _gt(mesh: TriMesh) -> GroundTruth:
    def faces_of(vids):
        return np.flatnonzero(np.isin(mesh.faces, vids).all(1))

    door = np.arange(0, 20 * 8)  # x rows 0..7
    drawer = np.arange(20 * 10, 20 * 16)
    handle = np.arange(20 * 17, 20 * 18)
    return GroundTruth("scanA", [
        GTPart(1, "cabinet.door", faces_of(door), door, Articulation(joint_type="revolute", axis=[0, 0, 1], origin=[0, 0, 0]), [0]),
        GTPart(2, "cabinet.drawer", faces_of(drawer), drawer, Articulation(joint_type="prismatic", axis=[0, -1, 0], origin=[0, 0, 0]), [0]),
        GTPart(3, "cabinet.door.handle", faces_of(handle), handle),
        GTPart(4, "fridge.door", faces_of(np.arange(360, 400)), np.arange(360, 400),
               Articulation(joint_type="revolute", axis=[1, 0, 0], origin=[0, 0, 0.9]), [0]),
    ], mesh.n_faces, mesh.n_vertices)


@pytest.fixture()
def gt_pred(tmp_path: Path) -> tuple[Path, Path]:
    mesh = _grid()
    save_mesh(tmp_path / "scan.ply", mesh)
    gt = _gt(mesh)
    write_articulate3d(tmp_path / "gt", gt)
    gt_to_scene(gt, tmp_path / "scan.ply", tmp_path / "pred")
    return tmp_path / "pred", tmp_path / "gt"


def test_gt_against_itself_is_perfect(gt_pred, tmp_path):
    res = run_evaluation(*gt_pred, out_dir=tmp_path / "rep")
    for tau in ("0.25", "0.5"):
        a = res["aggregate"][tau]
        assert a["f1"] == 1.0 and a["precision"] == 1.0 and a["recall"] == 1.0
        assert a["joint_acc"] == 1.0 and a["oe"] == pytest.approx(0.0, abs=1e-6) and a["md"] == pytest.approx(0.0, abs=1e-9)
        assert (a["pdet"], a["m"], a["mo"], a["mod"]) == (1.0, 1.0, 1.0, 1.0)
    assert res["scenes"][0]["n_gt"] == 3 and res["scenes"][0]["faces"] == _grid().n_faces
    parts = pq.read_table(tmp_path / "rep" / "parts.parquet").to_pylist()
    assert len(parts) == 6 and all(p["mod"] for p in parts)
    assert "+MOD" in (tmp_path / "rep" / "metrics.md").read_text()


def test_evaluate_cli_on_gt_folder(gt_pred, tmp_path, capsys):
    out = tmp_path / "m.json"
    assert main(["evaluate", str(gt_pred[0]), str(gt_pred[1]), "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["aggregate"]["0.5"]["mod"] == 1.0
    assert "| REACT3D |" in capsys.readouterr().out


def test_evaluate_multi_scene_layout_and_bad_input(gt_pred, tmp_path):
    (tmp_path / "preds").mkdir()
    gt_pred[0].rename(tmp_path / "preds" / "scanA")
    (tmp_path / "preds" / "scanA" / "scene.json").write_text(
        (tmp_path / "preds" / "scanA" / "scene.json").read_text().replace('"input_mesh": "../', '"input_mesh": "../../'))
    res = run_evaluation(tmp_path / "preds", gt_pred[1])
    assert [s["scene"] for s in res["scenes"]] == ["scanA"]
    with pytest.raises(InputError):
        run_evaluation(tmp_path / "nowhere", gt_pred[1])
    assert main(["evaluate", str(tmp_path / "nowhere"), str(gt_pred[1])]) == 2


def test_prefect_flow_body(gt_pred, tmp_path):
    from flows.evaluate import evaluate

    res = evaluate.fn(str(gt_pred[0]), str(gt_pred[1]), str(tmp_path / "rep"))
    assert res["aggregate"]["0.25"]["f1"] == 1.0
    assert json.loads((tmp_path / "rep" / "metrics.json").read_text())["aggregate"] == res["aggregate"]
