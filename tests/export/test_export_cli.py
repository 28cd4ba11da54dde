"""``linkwork export``: STL/3MF solids read back by trimesh (every part one closed, outward-oriented body, placed
where points.csv says the joints are), and the MJCF model run in the real MuJoCo simulator (its loop welds hold at
our traced configurations, and driving the drive joint moves it along our path)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner, Result

from linkwork.cli import app

trimesh = pytest.importorskip("trimesh")
mujoco = pytest.importorskip("mujoco")
pytest.importorskip("networkx")  # trimesh's 3MF reader

runner = CliRunner()


def invoke(*args: str) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert "Traceback" not in result.stdout + result.stderr
    return result


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("traces")
    runs = {
        "four-bar": ["four-bar", "--drive", "A", "--until", "A=400"],
        "hoop": ["hedgepeth-rods", "--set", "n=6"],
        "bennett": ["bennett", "--drive", "A", "--until", "A=100"],
    }
    for name, args in runs.items():
        result = invoke("trace", *args, "--no-plots", "--out", root / name)
        assert result.exit_code == 0, result.stderr
    return {name: root / name for name in runs}


def _points(folder: Path) -> tuple[list[str], np.ndarray]:
    with open(folder / "points.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.parametrize(("name", "suffix"), [("hoop", ".stl"), ("hoop", ".3mf"), ("four-bar", ".stl")])
def test_every_part_is_one_closed_solid(
    traces: dict[str, Path], tmp_path: Path, name: str, suffix: str
) -> None:
    out = tmp_path / f"model{suffix}"
    result = invoke("export", "stl", traces[name], "--point", "7", "-o", out)
    assert result.exit_code == 0, result.stderr
    scene = trimesh.load(out, force="scene")
    n_bodies, n_joints = (6, 6) if name == "hoop" else (4, 4)
    assert len(scene.geometry) == n_bodies + n_joints  # one solid per link and per pin
    for mesh in scene.geometry.values():
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.is_volume
        assert mesh.volume > 0.0
        assert len(mesh.split(only_watertight=False)) == 1  # one connected body per part


def test_pins_sit_where_points_csv_puts_the_joints(traces: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "four_bar.stl"
    assert invoke("export", "stl", traces["four-bar"], "--point", "40", "-o", out).exit_code == 0
    scene = trimesh.load(out, force="scene")
    header, rows = _points(traces["four-bar"])
    row = rows[(rows[:, 0] == 0) & (rows[:, 1] == 40)][0]
    for joint in "ABCD":
        pin = scene.geometry[f"pin_{joint}"]
        xy = [row[header.index(f"{joint}_x")], row[header.index(f"{joint}_y")]]
        # a pin is a prism round its axis (a z-line through the joint): its bounding box centre is on the axis
        np.testing.assert_allclose(pin.bounds.mean(axis=0)[:2], xy, atol=1e-6)


def test_scale_multiplies_every_length(traces: dict[str, Path], tmp_path: Path) -> None:
    one, hundred = tmp_path / "one.stl", tmp_path / "hundred.stl"
    assert invoke("export", "stl", traces["hoop"], "-o", one).exit_code == 0
    assert invoke("export", "stl", traces["hoop"], "--scale", "100", "-o", hundred).exit_code == 0
    a, b = (trimesh.load(f, force="scene").bounds for f in (one, hundred))
    np.testing.assert_allclose(b, 100.0 * a, rtol=1e-7, atol=1e-6)


def test_bad_export_requests_are_one_line_exit_2(traces: dict[str, Path], tmp_path: Path) -> None:
    for args in (
        ["stl", traces["hoop"], "-o", tmp_path / "x.obj"],
        ["stl", traces["hoop"], "--branch", "9", "-o", tmp_path / "x.stl"],
        ["stl", traces["hoop"], "--point", "100000", "-o", tmp_path / "x.stl"],
        ["stl", tmp_path, "-o", tmp_path / "x.stl"],
    ):
        result = invoke("export", *args)
        assert result.exit_code == 2 and result.stderr.count("\n") == 1, result.stderr
    assert not (tmp_path / "x.stl").exists() and not (tmp_path / "x.obj").exists()


def _model(path: Path) -> tuple[object, object]:
    model = mujoco.MjModel.from_xml_path(str(path))
    return model, mujoco.MjData(model)


def _traced(folder: Path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Joint names, displacements q = value - start value (radians) of every traced point, start values."""
    with open(folder / "path.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    import tomllib

    spec = tomllib.loads((folder / "mechanism.toml").read_text())
    joints = spec.get("loop", spec.get("mechanism"))["joints"]
    names = [j["name"] for j in joints]
    start = np.radians([j.get("theta", j.get("value", 0.0)) for j in joints])
    values = np.radians(np.array([[float(r[rows[0].index(n)]) for n in names] for r in rows[1:]]))
    return names, values - start, start


@pytest.mark.parametrize("name", ["four-bar", "hoop", "bennett"])
def test_mjcf_loops_close_at_our_traced_points(traces: dict[str, Path], tmp_path: Path, name: str) -> None:
    out = tmp_path / "model.xml"
    assert invoke("export", "mjcf", traces[name], "-o", out).exit_code == 0
    model, data = _model(out)
    names, q, _ = _traced(traces[name])
    assert model.neq == 1  # one loop, one weld (no couplings in these three)
    adr = [model.jnt_qposadr[model.joint(n).id] for n in names]  # hinges named after our joints
    equality = mujoco.mjtConstraint.mjCNSTR_EQUALITY
    worst = 0.0
    for row in q:
        data.qpos[adr] = row
        mujoco.mj_forward(model, data)
        worst = max(worst, float(np.abs(data.efc_pos[data.efc_type == equality]).max()))
    assert worst < 1e-6
    data.qpos[adr] = q[len(q) // 2] + np.eye(len(names))[1] * 0.01  # one joint off the path: the weld sees it
    mujoco.mj_forward(model, data)
    assert np.abs(data.efc_pos[data.efc_type == equality]).max() > 1e-3


@pytest.mark.parametrize("name", ["four-bar", "bennett"])
def test_driving_the_drive_joint_follows_our_path(traces: dict[str, Path], tmp_path: Path, name: str) -> None:
    out = tmp_path / "model.xml"
    assert invoke("export", "mjcf", traces[name], "-o", out).exit_code == 0
    model, data = _model(out)
    names, q, _ = _traced(traces[name])
    adr = [model.jnt_qposadr[model.joint(n).id] for n in names]
    q = q[: np.argmax(q[:, 0] >= np.radians(30.0))]  # the first 30 deg of the drive A, increasing
    assert np.all(np.diff(q[:, 0]) > 0) and len(q) > 10
    steps = 1500
    worst = 0.0
    for k in range(steps):
        data.ctrl[0] = q[-1, 0] * min(1.0, (k + 1) / 1000)  # ramp the position actuator over 1 s
        mujoco.mj_step(model, data)
        drive = data.qpos[adr[0]]
        if k % 25 == 0 and q[0, 0] <= drive <= q[-1, 0]:
            ours = [np.interp(drive, q[:, 0], q[:, j]) for j in range(len(names))]
            worst = max(worst, float(np.abs(data.qpos[adr] - ours).max()))
    assert data.qpos[adr[0]] > 0.9 * q[-1, 0]  # it moved most of the way
    assert worst < 1e-3  # radians: the welds are soft constraints (solimp 0.9999)


def test_mjcf_keeps_the_couplings_of_the_eight_rod_hoop() -> None:
    """Hedgepeth's eight-rod hoop has mobility 3 without the paper's symmetry A = C = E = G, B = D = F = H: the
    model carries it as joint equalities, so the traced path satisfies every constraint and the model's free
    motion is the traced one (the constraint Jacobian leaves one direction: rank 8 - 1)."""
    import linkwork as lw
    from linkwork.export.mjcf import mjcf

    mech = lw.load("hedgepeth-rods", n=8)
    model = mujoco.MjModel.from_xml_string(mjcf(mech, "A"))
    data = mujoco.MjData(model)
    assert model.neq == 1 + 6  # one weld, six couplings
    adr = [model.jnt_qposadr[model.joint(n).id] for n in mech.joint_names]
    tr = lw.trace(mech, steps=20, until=("A", mech.offsets[0] + np.radians(60.0)))
    equality = mujoco.mjtConstraint.mjCNSTR_EQUALITY
    for row in tr.angles:
        data.qpos[adr] = row - mech.offsets
        mujoco.mj_forward(model, data)
        assert np.abs(data.efc_pos[data.efc_type == equality]).max() < 1e-6
    J = data.efc_J.reshape(data.nefc, model.nv)[data.efc_type == equality]
    sigma = np.linalg.svd(J, compute_uv=False)
    assert np.sum(sigma > 1e-8 * sigma[0]) == model.nv - 1  # mobility one, as traced
