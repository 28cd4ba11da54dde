"""Linkage spec files: the conventions give the classical linkages, dump/load round trips, and bad input is
one clear line naming the file and the key.

References are from outside the code: Bennett's closed-form joint relation, Gruebler's count for planar
linkages, the built-in Hedgepeth hoop (the paper's Eqs. 7-12), and invariants under a rigid motion of the base
frame (the angle and the reciprocal product of two joint twists).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.errors import AssemblyError, SpecError
from linkwork.io.spec import LoadedSpec, dump_spec, load_spec, resolve_spec
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import numerical_rank

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "specs"

ALPHA1, ALPHA2 = math.radians(45.0), math.radians(75.0)
#: Bennett's joint relation tan(t1/2) tan(t2/2) = sin((a2 + a1)/2) / sin((a2 - a1)/2) (Bennett 1903).
BENNETT_K = math.sin((ALPHA2 + ALPHA1) / 2.0) / math.sin((ALPHA2 - ALPHA1) / 2.0)


def rank_at_start(mech: Mechanism) -> int:
    """Numerical rank of the closure Jacobian at the reference configuration."""
    sigma = np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)), compute_uv=False)
    return numerical_rank(sigma)


def residual_at_start(mech: Mechanism) -> float:
    return float(np.linalg.norm(closure_residual(mech, np.zeros(mech.n_joints))))


def bennett_relation(mech: Mechanism) -> float:
    """Left minus right side of Bennett's relation at the start (joints A and B)."""
    t1, t2 = mech.offsets[0], mech.offsets[1]
    return math.tan(t1 / 2.0) * math.tan(t2 / 2.0) - BENNETT_K


def twist_invariants(mech: Mechanism) -> tuple[np.ndarray, np.ndarray]:
    """Pairwise ``omega_i . omega_j`` and reciprocal products ``omega_i . v_j + omega_j . v_i``.

    Both are unchanged by a rigid motion of the base frame.
    """
    w, v = mech.twists[:, :3], mech.twists[:, 3:]
    return w @ w.T, w @ v.T + v @ w.T


def write(tmp_path: Path, text: str, name: str = "spec.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def bennett_dh_text(thetas_deg: list[float], angles: str = "deg") -> str:
    """The Bennett 45/75 in the dh convention with the given start angles."""
    a2 = (1.0 + math.sqrt(3.0)) / 2.0  # a2 / sin 75 = 1 / sin 45
    conv = (lambda x: x) if angles == "deg" else math.radians
    rows = [f'name = "Bennett"\nangles = "{angles}"\n\n[loop]\nconvention = "dh"\n']
    for theta, a, alpha in zip(thetas_deg, [1.0, a2, 1.0, a2], [45.0, 75.0, 45.0, 75.0], strict=True):
        rows.append(f"[[loop.joints]]\ntheta = {conv(theta)!r}\na = {a!r}\nalpha = {conv(alpha)!r}\n")
    return "\n".join(rows)


def bennett_thetas() -> list[float]:
    t1 = 90.0
    t2 = math.degrees(2.0 * math.atan(BENNETT_K / math.tan(math.radians(t1) / 2.0)))
    return [t1, t2, -t1, -t2]


# ----------------------------------------------------------------------------------------------------------
# the conventions give the classical linkages
def test_bennett_dh_closes_and_obeys_bennetts_relation() -> None:
    spec = load_spec(EXAMPLES / "bennett-dh.toml")
    mech = spec.mechanism
    assert residual_at_start(mech) < 1e-12
    assert abs(bennett_relation(mech)) < 1e-12 * BENNETT_K
    assert rank_at_start(mech) == 3  # mobility 1 for 4 joints
    assert spec.assembly is not None and spec.max_correction < 1e-12


def test_bennett_hinge_lines_equal_dh_up_to_a_rigid_motion_of_the_base(tmp_path: Path) -> None:
    dh = load_spec(EXAMPLES / "bennett-dh.toml").mechanism
    # Move the example's hinge lines by a rigid motion and write them as a new hinge-lines file.
    rng = np.random.default_rng(7)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = 1.1
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K
    shift = rng.normal(size=3)
    lines = load_spec(EXAMPLES / "bennett-hinge-lines.toml").mechanism
    text = ['[loop]\nconvention = "hinge-lines"\n']
    for j in range(4):
        w, v = lines.twists[j, :3], lines.twists[j, 3:]
        point = R @ np.cross(w, v) + shift
        text.append(
            f"[[loop.joints]]\npoint = {point.tolist()}\ndirection = {(R @ w).tolist()}\n"
            f"theta = {math.degrees(lines.offsets[j])!r}\n"
        )
    moved = load_spec(write(tmp_path, "\n".join(text), "moved.toml")).mechanism
    for mech in (lines, moved):
        assert residual_at_start(mech) < 1e-12
        assert rank_at_start(mech) == 3
        assert abs(bennett_relation(mech)) < 1e-12 * BENNETT_K
        for got, want in zip(twist_invariants(mech), twist_invariants(dh), strict=True):
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        np.testing.assert_allclose(mech.offsets, dh.offsets, rtol=0, atol=1e-12)


def test_rounded_dh_start_is_corrected_onto_the_loop(tmp_path: Path) -> None:
    rounded = [round(t, 2) for t in bennett_thetas()]
    spec = load_spec(write(tmp_path, bennett_dh_text(rounded)))
    assert spec.assembly is not None
    assert spec.assembly.residual_before > 1e-6  # the rounded start did not close
    assert 0.0 < math.degrees(spec.max_correction) < 0.02  # a correction of the order of the rounding
    assert spec.assembly.residual_after < 1e-12
    assert residual_at_start(spec.mechanism) < 1e-12
    # The corrected start lies on the Bennett loop, so Bennett's relation holds there.
    assert abs(bennett_relation(spec.mechanism)) < 1e-10 * BENNETT_K


def test_angles_in_radians_give_the_same_loop(tmp_path: Path) -> None:
    deg = load_spec(write(tmp_path, bennett_dh_text(bennett_thetas()), "deg.toml")).mechanism
    rad = load_spec(write(tmp_path, bennett_dh_text(bennett_thetas(), "rad"), "rad.toml")).mechanism
    np.testing.assert_allclose(rad.twists, deg.twists, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rad.offsets, deg.offsets, rtol=0, atol=1e-12)


def test_planar_four_bar_has_rank_3_and_mobility_1() -> None:
    mech = load_spec(EXAMPLES / "four-bar.toml").mechanism
    assert mech.planar and len(mech.loops) == 1 and mech.n_joints == 4
    assert residual_at_start(mech) < 1e-12
    rank = rank_at_start(mech)
    assert rank == 3
    assert mech.n_joints - rank == 1  # Gruebler: 3 (4 - 1) - 2 * 4 = 1
    assert math.degrees(mech.offsets[0]) == pytest.approx(45.0, abs=1e-12)


def test_watt_six_bar_has_two_loops_rank_6_and_mobility_1() -> None:
    mech = load_spec(EXAMPLES / "watt-six-bar.toml").mechanism
    assert len(mech.loops) == 2 and mech.n_joints == 7
    rank = rank_at_start(mech)
    assert rank == 6
    assert mech.n_joints - rank == 1  # Gruebler: 3 (6 - 1) - 2 * 7 = 1


SLIDER_CRANK = """
name = "slider-crank"
[mechanism]
planar = true
fixed = ["E"]

[[mechanism.joints]]
name = "A"
bodies = ["ground", "crank"]
point = [0.0, 0.0]
value = 60.0

[[mechanism.joints]]
name = "B"
bodies = ["crank", "rod"]
point = [0.5, 0.8660254037844386]

[[mechanism.joints]]
name = "C"
bodies = ["rod", "slider"]
point = [2.3027756377319946, 0.0]

[[mechanism.joints]]
name = "D"
type = "P"
bodies = ["slider", "ground"]
direction = [1.0, 0.0]
value = 2.3027756377319946

[[mechanism.joints]]
name = "E"
bodies = ["slider", "flag"]
point = [2.3027756377319946, 1.0]
"""


def test_slider_crank_with_a_prismatic_joint(tmp_path: Path) -> None:
    mech = load_spec(write(tmp_path, SLIDER_CRANK)).mechanism
    assert mech.joint_types == ("R", "R", "R", "P", "R")
    np.testing.assert_allclose(mech.twists[3], [0, 0, 0, 1, 0, 0], rtol=0, atol=1e-15)
    assert mech.offsets[3] == pytest.approx(2.3027756377319946, abs=1e-15)  # a length, not converted
    assert rank_at_start(mech) == 3  # one loop; E hangs off the slider and is fixed
    assert mech.n_unknowns == 4 and list(np.flatnonzero(mech.groups < 0)) == [4]


def test_hedgepeth_rods_equal_the_builtin() -> None:
    from linkwork.linkages.hedgepeth import hedgepeth

    spec = load_spec(EXAMPLES / "hedgepeth-4-rods.toml").mechanism
    builtin = hedgepeth(4)
    assert spec.joint_names == builtin.joint_names
    np.testing.assert_allclose(spec.twists, builtin.twists, rtol=0, atol=1e-12)
    np.testing.assert_allclose(spec.offsets, builtin.offsets, rtol=0, atol=1e-12)


def test_couplings_are_applied(tmp_path: Path) -> None:
    text = (
        (EXAMPLES / "bennett-dh.toml")
        .read_text()
        .replace('convention = "dh"', 'convention = "dh"\ncouple = [["A", "C"]]\nfixed = ["B"]')
    )
    mech = load_spec(write(tmp_path, text)).mechanism
    assert mech.group_members() == [[0, 2], [3]]
    assert mech.groups[1] == -1


# ----------------------------------------------------------------------------------------------------------
# dump and load round trips
def assert_same_mechanism(got: Mechanism, want: Mechanism) -> None:
    assert got.joint_names == want.joint_names
    assert got.joint_types == want.joint_types
    assert got.planar == want.planar
    np.testing.assert_allclose(got.twists, want.twists, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.offsets, want.offsets, rtol=0, atol=1e-12)
    assert got.loops == want.loops
    assert got.joint_bodies == want.joint_bodies
    assert got.group_members() == want.group_members()
    np.testing.assert_array_equal(got.groups < 0, want.groups < 0)


def builtin_cases() -> list[tuple[str, dict[str, float]]]:
    from linkwork.io.spec import import_builtins
    from linkwork.linkages.registry import REGISTRY

    import_builtins()
    cases: list[tuple[str, dict[str, float]]] = [(name, {}) for name in sorted(REGISTRY)]
    if "hedgepeth" in REGISTRY:
        cases += [("hedgepeth", {"n": 4}), ("hedgepeth", {"n": 10})]  # n = 10 carries couplings
    return cases


@pytest.mark.parametrize(("name", "params"), builtin_cases())
def test_dump_load_round_trip_of_builtins(tmp_path: Path, name: str, params: dict[str, float]) -> None:
    mech = resolve_spec(name, params).mechanism
    assert_same_mechanism(load_spec(write(tmp_path, dump_spec(mech))).mechanism, mech)


@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_dump_load_round_trip_of_examples(tmp_path: Path, example: str) -> None:
    mech = load_spec(EXAMPLES / example).mechanism
    assert_same_mechanism(load_spec(write(tmp_path, dump_spec(mech))).mechanism, mech)


def test_dump_load_round_trip_with_prismatic_joint_and_fixed_joint(tmp_path: Path) -> None:
    mech = load_spec(write(tmp_path, SLIDER_CRANK)).mechanism
    text = dump_spec(mech)
    assert text.startswith("# ")
    assert_same_mechanism(load_spec(write(tmp_path, text, "again.toml")).mechanism, mech)


def test_dump_escapes_names(tmp_path: Path) -> None:
    mech = load_spec(EXAMPLES / "four-bar.toml").mechanism
    from dataclasses import replace

    odd = replace(mech, name='a "quoted"\\ name\twith\ttabs')
    assert load_spec(write(tmp_path, dump_spec(odd))).mechanism.name == odd.name


# ----------------------------------------------------------------------------------------------------------
# resolving a spec argument
def test_resolve_builtin_and_file() -> None:
    built = resolve_spec("hedgepeth", {"n": 4})
    assert isinstance(built, LoadedSpec) and built.source is None and built.assembly is None
    assert built.mechanism.n_joints == 4
    from_file = resolve_spec(str(EXAMPLES / "four-bar.toml"), {})
    assert from_file.source == EXAMPLES / "four-bar.toml"


def test_resolve_rejects_set_for_a_file() -> None:
    with pytest.raises(SpecError, match=r"four-bar\.toml: --set: --set applies to built-in linkages only"):
        resolve_spec(EXAMPLES / "four-bar.toml", {"n": 4})


def test_resolve_unknown_builtin() -> None:
    with pytest.raises(SpecError, match="unknown linkage 'nosuch'"):
        resolve_spec("nosuch", {})


# ----------------------------------------------------------------------------------------------------------
# bad input: one line naming the file, the key and what was expected
HEAD = 'name = "t"\n'
DH4 = "".join(f"[[loop.joints]]\ntheta = 0.0\na = 1.0\nalpha = {a}\n" for a in (10.0, 20.0, 30.0, 40.0))
LOOP_DH = HEAD + '[loop]\nconvention = "dh"\n' + DH4
HINGE = (
    HEAD
    + '[loop]\nconvention = "hinge-lines"\n'
    + "".join(
        f"[[loop.joints]]\npoint = [{x}, 0.0, 0.0]\ndirection = [0.0, {y}, 1.0]\n"
        for x, y in ((0, 0), (1, 1), (2, 0), (3, 1))
    )
)
FOUR_BAR = (EXAMPLES / "four-bar.toml").read_text()

BAD_CASES = {
    "toml syntax": ('name = "t"\n[loop\nconvention = "dh"\n', "line 2, column 6", "invalid TOML"),
    "toml syntax at end": ('name = "t"\nangles =', "line 2 (end of file)", "invalid TOML"),
    "unknown top key": ('nmae = "t"\n' + LOOP_DH[len(HEAD) :], "nmae", 'did you mean "name"'),
    "unknown loop key": (
        LOOP_DH.replace("convention", "conventoin"),
        "loop.conventoin",
        'did you mean "convention"',
    ),
    "unknown joint key": (
        LOOP_DH.replace("alpha = 30.0", "alpah = 30.0"),
        "loop.joints[2].alpah",
        'did you mean "alpha"',
    ),
    "key of another convention": (
        LOOP_DH.replace("a = 1.0\nalpha = 30.0", "a = 1.0\nalpha = 30.0\npoint = [0, 0, 0]"),
        "loop.joints[2].point",
        'belongs in [[loop.joints]] (convention "hinge-lines")',
    ),
    "unknown rod key": (
        HEAD
        + '[loop]\nconvention = "rods"\n'
        + "[[loop.joints]]\nrod = { phi = 0, omgea = 0, psi = 0, v = [1, 0, 0] }\n" * 4,
        "loop.joints[0].rod.omgea",
        'did you mean "omega"',
    ),
    "unknown mechanism key": (FOUR_BAR.replace("planar = true", "planr = true"), "mechanism.planr", "planar"),
    "unknown mechanism joint key": (
        FOUR_BAR.replace(
            'type = "R"\nbodies = ["crank", "coupler"]', 'typ = "R"\nbodies = ["crank", "coupler"]'
        ),
        "mechanism.joints[1].typ",
        'did you mean "type"',
    ),
    "number expected": (
        LOOP_DH.replace("alpha = 30.0", 'alpha = "abc"'),
        "loop.joints[2].alpha",
        'expected a number, got "abc"',
    ),
    "boolean is not a number": (LOOP_DH.replace("a = 1.0", "a = true", 1), "loop.joints[0].a", "got true"),
    "bool expected": (
        FOUR_BAR.replace("planar = true", 'planar = "yes"'),
        "mechanism.planar",
        "true or false",
    ),
    "table expected": (HEAD + "loop = 3\n", "loop", "expected a table, got 3"),
    "array of tables expected": (
        HEAD + '[loop]\nconvention = "dh"\n[loop.joints]\ntheta = 1.0\n',
        "loop.joints",
        "expected an array of tables [[loop.joints]]",
    ),
    "name not a string": (LOOP_DH.replace('name = "t"', "name = 3"), "name", "expected a non-empty string"),
    "vector length": (
        HINGE.replace("point = [2, 0.0, 0.0]", "point = [2, 0.0]"),
        "loop.joints[2].point",
        "expected a list of 3 numbers [x, y, z], got a list of 2",
    ),
    "vector element": (
        HINGE.replace("point = [2, 0.0, 0.0]", 'point = [2, "x", 0.0]'),
        "loop.joints[2].point[1]",
        'expected a number, got "x"',
    ),
    "vector not a list": (
        HINGE.replace("point = [2, 0.0, 0.0]", "point = 2"),
        "loop.joints[2].point",
        "expected a list of 3 numbers",
    ),
    "zero direction": (
        HINGE.replace("direction = [0.0, 1, 1.0]", "direction = [0.0, 0, 0.0]", 1),
        "loop.joints[1].direction",
        "expected a non-zero direction vector",
    ),
    "missing point": (HINGE.replace("point = [3, 0.0, 0.0]\n", ""), "loop.joints[3].point", "missing"),
    "missing rod": (
        HEAD + '[loop]\nconvention = "rods"\n' + "[[loop.joints]]\ntheta = 0\n" * 4,
        "loop.joints[0].rod",
        "missing; expected a rod table",
    ),
    "too few joints in a loop": (
        HEAD + '[loop]\nconvention = "dh"\n' + "[[loop.joints]]\na = 1.0\n" * 3,
        "loop.joints",
        "expected at least 4 joints in a closed loop",
    ),
    "too few joints in a planar loop": (
        HEAD
        + "[mechanism]\nplanar = true\n"
        + "".join(
            f'[[mechanism.joints]]\nbodies = ["{a}", "{b}"]\npoint = [{x}, 0]\n'
            for a, b, x in (("ground", "l1", 0), ("l1", "l2", 1), ("l2", "ground", 2))
        ),
        "mechanism.joints",
        "has 3 joints; a closed loop needs at least 4",
    ),
    "no loop": (
        HEAD + '[mechanism]\n[[mechanism.joints]]\nbodies = ["ground", "l1"]\npoint = [0, 0, 0]\n'
        "direction = [0, 0, 1]\n",
        "mechanism.joints",
        "form no closed loop",
    ),
    "no joints": (
        HEAD + '[loop]\nconvention = "dh"\n',
        "loop.joints",
        "missing; expected one [[loop.joints]]",
    ),
    "duplicate names": (
        LOOP_DH.replace("alpha = 30.0", 'alpha = 30.0\nname = "A"'),
        "loop.joints[2].name",
        'duplicate joint name "A" (also loop.joints[0])',
    ),
    "bad joint name": (
        LOOP_DH.replace("alpha = 30.0", 'alpha = 30.0\nname = "C 1"'),
        "loop.joints[2].name",
        "spaces",
    ),
    "unknown joint in couple": (
        LOOP_DH.replace('convention = "dh"', 'convention = "dh"\ncouple = [["A", "X"]]'),
        "loop.couple[0][1]",
        'unknown joint "X"; joints are A, B, C, D',
    ),
    "unknown joint in fixed": (
        LOOP_DH.replace('convention = "dh"', 'convention = "dh"\nfixed = ["a"]'),
        "loop.fixed[0]",
        'unknown joint "a"; did you mean "A"?',
    ),
    "coupling of one joint": (
        LOOP_DH.replace('convention = "dh"', 'convention = "dh"\ncouple = [["A"]]'),
        "loop.couple[0]",
        "expected at least two joints",
    ),
    "couple not a list of lists": (
        LOOP_DH.replace('convention = "dh"', 'convention = "dh"\ncouple = ["A", "C"]'),
        "loop.couple[0]",
        "expected a list of joint names",
    ),
    "coupling R with P": (
        SLIDER_CRANK.replace('fixed = ["E"]', 'couple = [["A", "D"]]'),
        "mechanism.couple[0]",
        "cannot couple revolute and prismatic joints",
    ),
    "both loop and mechanism": (LOOP_DH + "[mechanism]\nplanar = true\n", "mechanism", "got both"),
    "neither loop nor mechanism": (HEAD, "loop", "missing; expected a [loop] table"),
    "bad convention": (
        LOOP_DH.replace('"dh"', '"DH-params"'),
        "loop.convention",
        'expected one of "dh", "hinge-lines", "rods"',
    ),
    "missing convention": (LOOP_DH.replace('convention = "dh"\n', ""), "loop.convention", "missing"),
    "bad angles unit": (
        'angles = "degrees"\n' + LOOP_DH,
        "angles",
        'expected "deg" or "rad", got "degrees" (did you mean "deg"?)',
    ),
    "nan": (
        LOOP_DH.replace("alpha = 30.0", "alpha = nan"),
        "loop.joints[2].alpha",
        "expected a finite number",
    ),
    "inf in a vector": (
        HINGE.replace("point = [2, 0.0, 0.0]", "point = [2, inf, 0.0]"),
        "loop.joints[2].point[1]",
        "expected a finite number, got inf",
    ),
    "body joined to itself": (
        FOUR_BAR.replace('bodies = ["crank", "coupler"]', 'bodies = ["crank", "crank"]'),
        "mechanism.joints[1].bodies",
        'expected two different bodies, got "crank" joined to itself',
    ),
    "bodies not a pair": (
        FOUR_BAR.replace('bodies = ["crank", "coupler"]', 'bodies = ["crank"]'),
        "mechanism.joints[1].bodies",
        "expected the two bodies it joins",
    ),
    "disconnected bodies": (
        FOUR_BAR
        + '[[mechanism.joints]]\nname = "E"\nbodies = ["island", "rock"]\npoint = [9, 9]\n'
        + '[[mechanism.joints]]\nname = "F"\nbodies = ["rock", "island"]\npoint = [9, 8]\n',
        "mechanism.joints[4].bodies",
        'bodies "island", "rock" are not connected to "ground"',
    ),
    "bad joint type": (
        FOUR_BAR.replace(
            'type = "R"\nbodies = ["crank", "coupler"]', 'type = "H"\nbodies = ["crank", "coupler"]'
        ),
        "mechanism.joints[1].type",
        'expected "R" or "P", got "H"',
    ),
    "planar revolute axis off z": (
        FOUR_BAR.replace("point = [1.0, 1.0]", "point = [1.0, 1.0]\ndirection = [1, 0, 0]"),
        "mechanism.joints[1].direction",
        "turns about z",
    ),
    "planar prismatic out of plane": (
        SLIDER_CRANK.replace("direction = [1.0, 0.0]", "direction = [1.0, 0.0, 1.0]"),
        "mechanism.joints[3].direction",
        "expected a direction in the plane",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_CASES))
def test_bad_input_is_one_line_naming_file_and_key(tmp_path: Path, case: str) -> None:
    text, key, expected = BAD_CASES[case]
    path = write(tmp_path, text, "bad.toml")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {key}: "), message
    assert expected in message, message
    assert info.value.source == str(path) and info.value.key == key


def test_missing_file_is_named() -> None:
    with pytest.raises(SpecError, match=r"nowhere\.toml: file not found"):
        load_spec("nowhere.toml")


def test_binary_file_is_rejected(tmp_path: Path) -> None:
    path = tmp_path / "binary.toml"
    path.write_bytes(b"\xff\xfe\x00name")
    with pytest.raises(SpecError, match=r"binary\.toml: not a UTF-8 text file"):
        load_spec(path)


def test_start_that_cannot_be_assembled_names_the_file(tmp_path: Path) -> None:
    thetas = bennett_thetas()
    thetas[1] += 40.0  # far from the loop: no small correction closes it
    path = write(tmp_path, bennett_dh_text(thetas), "far.toml")
    with pytest.raises(AssemblyError) as info:
        load_spec(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    assert info.value.residual is not None and info.value.residual > 1e-3
