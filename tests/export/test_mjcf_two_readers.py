"""The MJCF export means the same to MuJoCo and to pinocchio: both load the model of every built-in with every
loop-closing weld satisfied at the start pose (``qpos0``) and at a traced pose, and both see a joint moved off the
path. pinocchio's constraint violation is computed from its constraint models' placements
(``log6(oMc1^-1 oMc2)``), MuJoCo's from ``mj_forward``'s equality residuals (``efc_pos``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.export.mjcf import mjcf
from linkwork.linkages import REGISTRY

mujoco = pytest.importorskip("mujoco")
pin = pytest.importorskip("pinocchio")

ROOT = Path(__file__).resolve().parents[2]
#: Every built-in, and a two-loop mechanism (Watt's six-bar: two welds).
CASES = [*sorted(REGISTRY), "watt-six-bar"]

#: Closure tolerance of a weld (lengths of about 1 and radians): round-off of the model's stored placements.
CLOSED = 1e-9
#: A joint turned 0.01 rad off the path opens some weld by at least this much.
OPEN = 1e-4


@pytest.fixture(scope="module", params=CASES)
def built_in(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> tuple[lw.Mechanism, Path, np.ndarray]:
    """A built-in, its MJCF file and the displacements q = value - start of a few traced points."""
    name = request.param
    mech = lw.load(name if name in REGISTRY else str(ROOT / "examples" / "specs" / f"{name}.toml"))
    path = tmp_path_factory.mktemp("mjcf") / f"{name}.xml"
    path.write_text(mjcf(mech))
    traced = lw.trace(mech, max_steps=12, max_step=np.radians(3.0))
    return mech, path, traced.angles - mech.offsets


def _pin_violations(path: Path, names: list[str], q_ours: np.ndarray | None) -> np.ndarray:
    """The size of every weld's violation in pinocchio at qpos0 (``q_ours`` None) or at ``q_ours``."""
    model, points, frames = pin.buildModelAndConstraintsFromMJCF(str(path))
    q = np.array(model.referenceConfigurations["qpos0"])
    if q_ours is not None:
        for name, value in zip(names, q_ours, strict=True):
            q[model.joints[model.getJointId(name)].idx_q] = value
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    out = []
    for c in [*frames, *points]:
        oMc1 = data.oMi[c.joint1_id] * c.joint1_placement
        oMc2 = data.oMi[c.joint2_id] * c.joint2_placement
        error = pin.log6(oMc1.inverse() * oMc2).vector
        out.append(np.linalg.norm(error if c in frames else oMc1.translation - oMc2.translation))
    return np.array(out)


def _mujoco_violations(path: Path, names: list[str], q_ours: np.ndarray | None) -> np.ndarray:
    """MuJoCo's equality residuals (welds and joint couplings) at qpos0 or at ``q_ours``."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    if q_ours is not None:
        data.qpos[[model.jnt_qposadr[model.joint(n).id] for n in names]] = q_ours
    mujoco.mj_forward(model, data)
    return np.abs(data.efc_pos[data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY])


def test_both_readers_find_every_loop_closed_at_the_start(
    built_in: tuple[lw.Mechanism, Path, np.ndarray],
) -> None:
    mech, path, _ = built_in
    loops = mech.n_joints - len(mech.bodies) + 1  # independent loops of the body graph: one weld each
    _, points, frames = pin.buildModelAndConstraintsFromMJCF(str(path))
    assert len(frames) == loops == len(mech.loops) and len(points) == 0
    assert _pin_violations(path, mech.joint_names, None).max() < CLOSED
    assert _mujoco_violations(path, mech.joint_names, None).max() < CLOSED


def test_both_readers_find_every_loop_closed_along_the_path(
    built_in: tuple[lw.Mechanism, Path, np.ndarray],
) -> None:
    mech, path, q = built_in
    assert len(q) > 5
    for row in q[1:]:
        assert _pin_violations(path, mech.joint_names, row).max() < 1e3 * CLOSED
        assert _mujoco_violations(path, mech.joint_names, row).max() < 1e3 * CLOSED


def test_both_readers_see_a_joint_off_the_path(built_in: tuple[lw.Mechanism, Path, np.ndarray]) -> None:
    mech, path, q = built_in
    off = q[len(q) // 2].copy()
    moving = int(np.flatnonzero(mech.groups >= 0)[0]) if np.any(mech.groups >= 0) else 0
    off[moving] += 0.01
    assert _pin_violations(path, mech.joint_names, off).max() > OPEN
    assert _mujoco_violations(path, mech.joint_names, off).max() > OPEN
