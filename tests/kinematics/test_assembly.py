"""Assembly keeps the link geometry written in a spec file exact, and says when the link parameters close no loop.

References outside the code under test: Bennett's closed form (Bennett 1914; Baker 1979)
``tan(tA/2) tan(tB/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2)``, ``tC = -tA``, ``tD = -tB``;
the loop product of the written DH links or rods rebuilt here with ``scipy.spatial.transform.Rotation``; the
least-squares closure misfit found by ``scipy.optimize.least_squares`` from many starts.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import logm
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

import linkwork as lw
from linkwork.errors import AssemblyError
from linkwork.io.results import report_dict
from linkwork.io.spec import load_spec, resolve_spec
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import normalized_jacobian

ROOT = Path(__file__).resolve().parents[2]
BENNETT = ROOT / "examples" / "specs" / "bennett-dh.toml"
HEDGEPETH_RODS = ROOT / "examples" / "specs" / "hedgepeth-4-rods.toml"


# ------------------------------------------------------------------------------------------------------------
# outside references
def _rz(t: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("z", t).as_matrix()
    return T


def _rx(t: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("x", t).as_matrix()
    return T


def _shift(v: Sequence[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = v
    return T


def dh_loop(links: Sequence[tuple[float, float, float]], thetas: Sequence[float]) -> np.ndarray:
    """``prod Rz(theta) Tz(d) Tx(a) Rx(alpha)`` for links ``(d, a, alpha)`` (radians)."""
    G = np.eye(4)
    for (d, a, alpha), t in zip(links, thetas, strict=True):
        G = G @ _rz(t) @ _shift([0.0, 0.0, d]) @ _shift([a, 0.0, 0.0]) @ _rx(alpha)
    return G


def rods_loop(rods: Sequence[dict[str, object]], thetas: Sequence[float]) -> np.ndarray:
    """``prod [Rz(phi) Rx(omega) Rz(psi), v] Rz(theta)`` (the paper's Eq. 12), Euler angles via scipy."""
    G = np.eye(4)
    for rod, t in zip(rods, thetas, strict=True):
        C = np.eye(4)
        C[:3, :3] = Rotation.from_euler("ZXZ", [rod["phi"], rod["omega"], rod["psi"]]).as_matrix()  # type: ignore[list-item]
        C[:3, 3] = rod["v"]  # type: ignore[assignment]
        G = G @ C @ _rz(t)
    return G


def twist_log(G: np.ndarray) -> np.ndarray:
    """``log G`` as the twist ``(omega, v)``, from scipy's matrix logarithm."""
    L = np.real(logm(G))
    return np.array([L[2, 1], L[0, 2], L[1, 0], *L[:3, 3]])


def bennett_b(theta_a: np.ndarray, alpha1: float, alpha2: float) -> np.ndarray:
    """Bennett's closed form: tB from tA (same branch as the example file, tB in (0, 360) deg)."""
    k = math.sin((alpha2 + alpha1) / 2) / math.sin((alpha2 - alpha1) / 2)
    return 2.0 * np.arctan(k / np.tan(theta_a / 2.0))


def rounded(text: str, decimals: int) -> str:
    """A spec file's ``theta`` values rounded to ``decimals`` decimals."""
    return re.sub(r"theta = (-?[0-9.eE+-]+)", lambda m: f"theta = {round(float(m.group(1)), decimals)}", text)


def write(tmp_path: Path, text: str, name: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def smallest_sigma(mech: Mechanism) -> float:
    return float(np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)), compute_uv=False)[-1])


# ------------------------------------------------------------------------------------------------------------
# 9.1: rounded start angles, exact geometry
@pytest.fixture(scope="module")
def exact_bennett() -> lw.Trace:
    return lw.trace(load_spec(BENNETT).mechanism, until=("A", math.radians(150.0)))


@pytest.mark.parametrize("decimals", [2, 4, 6])
def test_bennett_with_rounded_angles_traces_the_exact_files_path(
    tmp_path: Path, decimals: int, exact_bennett: lw.Trace
) -> None:
    path = write(tmp_path, rounded(BENNETT.read_text(), decimals), f"bennett-{decimals}.toml")
    loaded = load_spec(path)
    mech = loaded.mechanism
    assert loaded.assembly is not None and loaded.assembly.residual_before > 1e-10
    assert loaded.assembly.misfit < 1e-14
    assert smallest_sigma(mech) < 1e-14  # still mobile: the rounding did not stiffen the loop
    trace = lw.trace(mech, until=("A", math.radians(150.0)))
    assert [b.end_reason for b in trace.branches] == ["reached target"]
    assert len(trace.angles) < 3 * len(exact_bennett.angles)
    np.testing.assert_allclose(trace.angles[-1], exact_bennett.angles[-1], atol=1e-9)
    # Every point lies on the loop of the written links, and on Bennett's closed form.
    links = [(0.0, 1.0, math.radians(45.0)), (0.0, (1 + math.sqrt(3)) / 2, math.radians(75.0))] * 2
    for angles in trace.angles[:: max(1, len(trace.angles) // 12)]:
        assert np.linalg.norm(dh_loop(links, angles) - np.eye(4)) < 1e-9
    tA, tB, tC, tD = trace.angles.T
    diff = np.angle(np.exp(1j * (tB - bennett_b(tA, math.radians(45.0), math.radians(75.0)))))
    assert np.max(np.abs(diff)) < 1e-9
    assert np.max(np.abs(tC + tA)) < 1e-9 and np.max(np.abs(tD + tB)) < 1e-9


def _goldberg_dh_text(decimals: int) -> tuple[str, list[tuple[float, float, float]]]:
    params = lw.load("goldberg").meta["params"]
    lines = ['name = "Goldberg 5R, rounded start"', 'angles = "deg"', "", "[loop]", 'convention = "dh"']
    links = []
    for p in params:
        links.append((p["d"], p["a"], p["alpha"]))
        lines += [
            "",
            "[[loop.joints]]",
            f"theta = {round(math.degrees(p['theta']), decimals)!r}",
            f"a = {p['a']!r}",
            f"alpha = {math.degrees(p['alpha'])!r}",
        ]
    return "\n".join(lines) + "\n", links


@pytest.mark.parametrize("decimals", [1, 4])
def test_goldberg_with_rounded_angles_traces_its_whole_motion(tmp_path: Path, decimals: int) -> None:
    text, links = _goldberg_dh_text(decimals)
    loaded = load_spec(write(tmp_path, text, "goldberg.toml"))
    assert loaded.assembly is not None and loaded.assembly.residual_before > 1e-8
    assert smallest_sigma(loaded.mechanism) < 1e-13
    trace = lw.trace(loaded.mechanism)
    assert [b.end_reason for b in trace.branches] == ["closed path"]
    assert trace.branches[0].steps < 2000
    for angles in trace.angles[:: max(1, len(trace.angles) // 20)]:
        assert np.linalg.norm(dh_loop(links, angles) - np.eye(4)) < 1e-9
    # The whole motion: joint A turns through a full revolution and comes back to its start.
    assert np.ptp(np.unwrap(trace.angles[:, 0])) > math.radians(359.0) or np.ptp(trace.angles[:, 0]) > 1.0
    np.testing.assert_allclose(np.cos(trace.angles[-1] - trace.angles[0]), 1.0, atol=1e-12)


@pytest.mark.parametrize("decimals", [2, 5])
def test_rods_loop_with_rounded_angles_keeps_the_written_rods(tmp_path: Path, decimals: int) -> None:
    exact = load_spec(HEDGEPETH_RODS)
    rods = exact.mechanism.meta["rods"]
    to60 = lw.trace(exact.mechanism, until=("A", math.radians(60.0)))
    start = np.degrees(to60.angles[-1])
    text = HEDGEPETH_RODS.read_text()
    for name, value in zip("ABCD", start, strict=True):
        text = re.sub(
            rf'(name = "{name}"\nrod = .*\n)theta = 0.0',
            rf"\g<1>theta = {round(float(value), decimals)}",
            text,
        )
    loaded = load_spec(write(tmp_path, text, "rods.toml"))
    assert loaded.assembly is not None and loaded.assembly.residual_before > 1e-9
    assert loaded.assembly.misfit < 1e-14
    trace = lw.trace(loaded.mechanism, until=("A", math.radians(80.0)))
    assert [b.end_reason for b in trace.branches] == ["reached target"]
    for angles in trace.angles[:: max(1, len(trace.angles) // 10)]:
        assert np.linalg.norm(rods_loop(rods, angles) - np.eye(4)) < 1e-9
    reference = lw.trace(exact.mechanism, until=("A", math.radians(80.0)))
    np.testing.assert_allclose(trace.angles[-1], reference.angles[-1], atol=1e-9)


def test_hinge_lines_with_rounded_readings_keep_their_lines(tmp_path: Path) -> None:
    """In the hinge-lines form the lines are the geometry; a rounded ``theta`` only shifts the reading."""
    source = ROOT / "examples" / "specs" / "bennett-hinge-lines.toml"
    exact = load_spec(source).mechanism
    mech = load_spec(write(tmp_path, rounded(source.read_text(), 1), "hl.toml")).mechanism
    np.testing.assert_array_equal(mech.twists, exact.twists)
    assert np.max(np.abs(mech.offsets - exact.offsets)) <= math.radians(0.05 + 1e-12)


# ------------------------------------------------------------------------------------------------------------
# 9.2 (load time): link parameters that close no loop
def _bennett_rounded_b(decimals: int) -> str:
    return BENNETT.read_text().replace("1.3660254037844386", repr(round((1 + math.sqrt(3)) / 2, decimals)))


def _outside_misfit(links: list[tuple[float, float, float]], closed: np.ndarray) -> float:
    """Least-squares minimum of |log G| over joints B, C, D with A held at ``closed[0]`` (scipy, logm).

    Along the motion the misfit of an inconsistent loop changes only slowly; with the drive held, the minimum
    over the other joints is well posed, and it is what the assembly leaves.
    """

    def residual(rest: np.ndarray) -> np.ndarray:
        return twist_log(dh_loop(links, np.concatenate([closed[:1], rest])))

    fit = least_squares(residual, closed[1:] + 1e-4, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return float(np.linalg.norm(fit.fun))


def test_rounded_link_length_is_diagnosed_in_one_line(tmp_path: Path) -> None:
    path = write(tmp_path, _bennett_rounded_b(3), "b3.toml")
    with pytest.raises(AssemblyError) as info:
        load_spec(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: ")
    match = re.search(r"least-squares closure misfit ([0-9.e+-]+) > closure tolerance 1e-12", message)
    assert match, message
    assert "smallest singular value" in message and "A-B-C-D" in message
    assert float(match.group(1)) == pytest.approx(
        resolve_spec(path, closure_tol=1.0).assembly.misfit, rel=1e-2
    )


def test_closure_tolerance_accepts_the_misfit_and_records_it(tmp_path: Path) -> None:
    path = write(tmp_path, _bennett_rounded_b(3), "b3.toml")
    with pytest.raises(AssemblyError):
        resolve_spec(path)
    loaded = resolve_spec(path, closure_tol=1e-3)
    assembly = loaded.assembly
    assert assembly is not None and 1e-7 < assembly.misfit <= 1e-3 and assembly.closure_tol == 1e-3
    # The misfit is that of the written loop at the assembled angles, and the least-squares minimum there.
    b = round((1 + math.sqrt(3)) / 2, 3)
    links = [(0.0, 1.0, math.radians(45.0)), (0.0, b, math.radians(75.0))] * 2
    closed = np.array(loaded.mechanism.offsets)
    assert np.linalg.norm(twist_log(dh_loop(links, closed))) == pytest.approx(assembly.misfit, rel=1e-6)
    # Stationary in the directions the Jacobian determines (finite differences of scipy's logm) ...
    err = twist_log(dh_loop(links, closed))
    h = 1e-7
    J = np.array(
        [
            (twist_log(dh_loop(links, closed + h * e)) - twist_log(dh_loop(links, closed - h * e))) / (2 * h)
            for e in np.eye(4)
        ]
    ).T
    U, s, _ = np.linalg.svd(J, full_matrices=False)
    assert s[3] < 1e-4 * s[0] < s[2]
    assert np.linalg.norm(U[:, :3].T @ err) < 1e-3 * np.linalg.norm(err)
    # ... and within a few percent of the least-squares minimum with joint A held (the misfit varies slowly
    # along the near-motion, so the two differ a little).
    held = _outside_misfit(links, closed)
    assert held <= assembly.misfit * (1 + 1e-6) and assembly.misfit <= 1.05 * held
    assert np.max(np.abs(assembly.correction)) < 1e-3  # stayed where the user put it
    assert assembly.sigma[-1] > 1e-9  # the written loop is (barely) rigid: its Jacobian has full rank
    trace = lw.trace(load_spec(BENNETT).mechanism, until=("A", math.radians(91.0)))
    report = report_dict(trace, assembly)
    assert report["assembly"]["misfit"] == assembly.misfit
    assert report["assembly"]["closure_tol"] == 1e-3


def test_cli_exits_2_on_rounded_link_length(tmp_path: Path) -> None:
    path = write(tmp_path, _bennett_rounded_b(3), "b3.toml")
    run = subprocess.run(
        [
            sys.executable,
            "-c",
            "from linkwork.cli import app; app()",
            "trace",
            str(path),
            "--out",
            str(tmp_path / "out"),
            "--no-plots",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "closure misfit" in lines[0] and "Traceback" not in run.stderr
    assert not (tmp_path / "out" / "report.json").exists()


# ------------------------------------------------------------------------------------------------------------
# 13.6: a Mechanism is a value
def test_mechanism_copies_and_freezes_its_arrays() -> None:
    twists = np.array([[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]] * 4)
    offsets = np.zeros(4)
    mech = Mechanism.single_loop("m", ["A", "B", "C", "D"], twists, offsets=offsets)
    twists[0, 2] = 5.0
    offsets[1] = 7.0
    assert mech.twists[0, 2] == 1.0 and mech.offsets[1] == 0.0
    for array in (mech.twists, mech.offsets, mech.groups):
        assert not array.flags.writeable
        with pytest.raises(ValueError):
            array[0] = 1
    coupled = mech.with_couplings([["A", "C"]])
    assert not coupled.groups.flags.writeable and coupled.twists is not twists


# ------------------------------------------------------------------------------------------------------------
# hinge lines a rounding away from a mobile linkage
def _rounded_lines(decimals: int) -> str:
    text = (ROOT / "examples" / "specs" / "bennett-hinge-lines.toml").read_text()

    def shorten(match: re.Match[str]) -> str:
        values = ", ".join(repr(round(float(x), decimals)) for x in match.group(2).split(","))
        return f"{match.group(1)}[{values}]"

    return re.sub(r"((?:point|direction) = )\[([^\]]*)\]", shorten, text)


@pytest.mark.parametrize("decimals", [3, 6])
def test_rounded_hinge_lines_are_diagnosed_and_accepted_within_tolerance(
    tmp_path: Path, decimals: int
) -> None:
    path = write(tmp_path, _rounded_lines(decimals), f"lines-{decimals}.toml")
    with pytest.raises(AssemblyError) as info:
        load_spec(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: ")
    assert "joints A, B, C, D" in message and "closure tolerance 1e-12" in message
    mech = load_spec(path, closure_tol=1e-3).mechanism
    # The number reported is what it says: one radian along the near-motion leaves that closure misfit.
    sigma = np.linalg.svd(jacobian(mech, np.zeros(4)), compute_uv=False)
    assert 1e-9 < sigma[-1] / sigma[0] < 1e-3  # rigid by a hair (a generic 4R loop is far from this)
    shown = float(re.search(r"closure misfit of ([0-9.e+-]+) per radian", message).group(1))  # type: ignore[union-attr]
    # Along the near-motion (the normalised Jacobian's last right singular vector), turning the most-moving
    # joint by h leaves h times that misfit: the closure residual itself, evaluated on the loop product.
    h = 1e-7  # second-order terms (h^2) stay far below the first-order misfit
    _, _, Vt = np.linalg.svd(normalized_jacobian(mech, mech.offsets))
    step = h * Vt[-1] / np.max(np.abs(Vt[-1]))
    assert np.linalg.norm(closure_residual(mech, step)) / h == pytest.approx(shown, rel=1e-2)
    assert shown > 0.5 * sigma[-1]


def test_hinge_lines_to_full_precision_load_without_a_word() -> None:
    assert load_spec(ROOT / "examples" / "specs" / "bennett-hinge-lines.toml").mechanism.n_joints == 4
