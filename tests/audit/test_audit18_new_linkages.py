"""Bookkeeping on linkages no earlier test traced, each against references written here or in the audit's own
``audit_reference`` (numpy; closures and Jacobians from the written joint lines, never linkwork's):

* slider linkages: an elliptic trammel (PRRP), a Scotch yoke (RRPP), an inverted slider-crank (RRPR), each from
  its closed form; the trammel also scaled by 1e-3 and 1e4 and turned and moved in its plane (the same rows);
* six-bars: a Stephenson chain and a Watt chain with every one of their six links held as the ground (the same
  rows in paper mode, every row closed), and a Watt II six-bar whose first loop is a parallelogram, traced in
  equal 1-deg steps that land exactly on both of its crossings (180 and 360 deg);
* a planar four-bar written as ``hinge-lines`` with every axis along (1, 2, 3) and moved: planar, and the same rows
  as written flat, also at x1000;
* a generic 7R (random ``dh`` parameters): closure and singular values against the audit's ``dh`` Jacobian, folds
  only where the drive turns back, the closed path's last row equal to its first;
* a line-symmetric Bricard loop with its symmetry written as couplings A=D, B=E, C=F: singular values of the
  Jacobian whose coupled columns add;
* every one of these exported to MJCF: MuJoCo's weld residuals vanish along the traced rows.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from audit_reference import DHLoop, Mech, dh, rot, wrap_deg
from scipy.optimize import least_squares

import linkwork as lw

RAD = np.pi / 180.0


def load(tmp_path: Path, name: str, text: str) -> lw.Mechanism:
    spec = tmp_path / f"{name}.toml"
    spec.write_text(text)
    return lw.load(str(spec))


def readings(mech: Mech, row: np.ndarray) -> dict[str, float]:
    """A trace row (radians, lengths) as the reference's readings (degrees, lengths)."""
    return {
        j["name"]: float(np.degrees(v)) if j["type"] == "R" else float(v)
        for j, v in zip(mech.joints, row, strict=True)
    }


def check_rows(mech: Mech, tr: lw.Trace, every: int = 1) -> tuple[float, float]:
    """Largest closure mismatch of the reference at the trace's rows, and largest difference of the trace's
    singular values from numpy's SVD of the reference Jacobian (relative to sigma_1)."""
    closure = sigma = 0.0
    for i in range(0, len(tr.angles), every):
        r = readings(mech, tr.angles[i])
        closure = max(closure, mech.poses(r)[1])
        s = np.linalg.svd(mech.jacobian(r), compute_uv=False)
        sigma = max(sigma, float(np.abs(s[: tr.sigma.shape[1]] - tr.sigma[i]).max() / s[0]))
    return closure, sigma


def loop_frame_jacobian(mech: Mech, r: dict[str, float]) -> np.ndarray:
    """The closure Jacobian with each loop's block in the frame of the body the loop starts from, held at its start
    pose (the audit's loops: fundamental cycles of a breadth-first tree from the ground); 3 rows a loop (planar)."""
    poses, _ = mech.poses(r)
    _, loops = mech.tree_and_loops()
    blocks = []
    for loop in loops:
        k0, s0 = loop[0]
        first = mech.joints[k0]["bodies"][0 if s0 > 0 else 1]
        to_first = np.linalg.inv(poses[first])
        block = np.zeros((6, len(mech.joints)))
        for k, s in loop:
            block[:, k] += s * mech.twist(k, to_first @ poses[mech.joints[k]["bodies"][0]])
        blocks.append(block[[2, 3, 4]] if mech.planar else block)
    return np.vstack(blocks)


# ------------------------------------------------------------------------------------------ slider linkages


def trammel(length: float = 2.0, phi0: float = 30.0) -> Mech:
    """Sliders X (on the x axis) and Y (on the y axis, written ground-last) joined by a bar of ``length``."""
    p1 = [length * np.cos(phi0 * RAD), 0.0, 0.0]
    p2 = [0.0, length * np.sin(phi0 * RAD), 0.0]
    return Mech(
        "trammel",
        [
            dict(
                name="X", type="P", bodies=["ground", "s1"], point=[0, 0, 0], direction=[1, 0, 0], value=p1[0]
            ),
            dict(name="A", bodies=["s1", "bar"], point=p1),
            dict(name="B", bodies=["bar", "s2"], point=p2),
            dict(
                name="Y", type="P", bodies=["s2", "ground"], point=[0, 0, 0], direction=[0, 1, 0], value=p2[1]
            ),
        ],
        planar=True,
    )


def scotch_yoke(r: float = 1.0, theta0: float = 40.0) -> Mech:
    """Crank A of radius ``r``; its pin B in a block sliding (C) along y in a yoke that slides (D) along x."""
    b = [r * np.cos(theta0 * RAD), r * np.sin(theta0 * RAD), 0.0]
    return Mech(
        "scotch-yoke",
        [
            dict(name="A", bodies=["ground", "crank"], point=[0, 0, 0], value=theta0),
            dict(name="B", bodies=["crank", "block"], point=b),
            dict(name="C", type="P", bodies=["block", "yoke"], point=b, direction=[0, 1, 0]),
            dict(name="D", type="P", bodies=["yoke", "ground"], point=[0, 0, 0], direction=[1, 0, 0]),
        ],
        planar=True,
    )


def inverted_slider_crank(theta0: float = 50.0, ground: float = 3.0) -> Mech:
    """Crank A (unit) from the origin; a block pinned at B slides (C) along the rocker, which turns about D."""
    b = np.array([np.cos(theta0 * RAD), np.sin(theta0 * RAD), 0.0])
    d = np.array([ground, 0.0, 0.0])
    return Mech(
        "inverted-slider-crank",
        [
            dict(name="A", bodies=["ground", "crank"], point=[0, 0, 0], value=theta0),
            dict(name="B", bodies=["crank", "block"], point=list(b)),
            dict(
                name="C",
                type="P",
                bodies=["block", "rocker"],
                point=list(b),
                direction=list((b - d) / np.linalg.norm(b - d)),
                value=float(np.linalg.norm(b - d)),
            ),
            dict(name="D", bodies=["rocker", "ground"], point=list(d)),
        ],
        planar=True,
    )


@pytest.mark.parametrize("steps", [None, 40])
def test_an_elliptic_trammel_keeps_its_closed_form(tmp_path: Path, steps: int | None) -> None:
    """The bar turns by A = -(phi - phi0) while X = 2 cos(phi) and Y reads 2 - 2 sin(phi) (1e-12); rows close to
    1e-12 and their singular values are numpy's to 1e-13 relative. Driven by X, it folds at X = +-2 exactly
    (1e-12) and its path closes, the last row equal to the first (revolute joints modulo 360 deg)."""
    ref = trammel()
    mech = load(tmp_path, "trammel", ref.toml())
    tr = lw.trace(mech, drive="A", until=("A", -2 * np.pi), steps=steps)
    phi = 30.0 * RAD - tr.angles[:, 1]
    np.testing.assert_allclose(tr.angles[:, 0], 2 * np.cos(phi), rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.angles[:, 3], 2.0 - 2 * np.sin(phi), rtol=0, atol=1e-12)
    closure, sigma = check_rows(ref, tr, every=3)
    assert closure < 1e-12 and sigma < 1e-13
    by_x = lw.trace(mech, drive="X", branches=True)
    assert sorted(f.value for f in by_x.folds) == pytest.approx([-2.0, 2.0], abs=1e-12)
    assert by_x.branches[0].end_kind == lw.StopReason.CLOSED
    first, last = by_x.angles[0], by_x.angles[-1]
    assert abs(last[0] - first[0]) < 1e-12 and abs(last[3] - first[3]) < 1e-12
    assert np.abs(wrap_deg(np.degrees(last[1:3] - first[1:3]))).max() < 1e-9
    np.testing.assert_allclose(by_x.sigma[-1], by_x.sigma[0], rtol=0, atol=1e-13)


def planar_motion(angle: float, shift: tuple[float, float]) -> np.ndarray:
    g = np.eye(4)
    g[:3, :3] = rot(np.array([0.0, 0.0, 1.0]), angle)
    g[:2, 3] = shift
    return g


@pytest.mark.parametrize("scale", [1e-3, 1e4])
def test_a_trammels_steps_do_not_depend_on_its_unit_or_place(tmp_path: Path, scale: float) -> None:
    """Lengths times 1e-3 or 1e4, and also turned 0.7 rad and moved: the same number of adaptive steps and the same
    rows (slider columns divided by the scale) to 1e-13."""
    ref = trammel()
    base = lw.trace(load(tmp_path, "t0", ref.toml()), drive="A", until=("A", 2 * np.pi))
    for motion in (None, planar_motion(0.7, (5.0 * scale, -3.0 * scale))):
        tr = lw.trace(load(tmp_path, "t1", ref.toml(scale, motion)), drive="A", until=("A", 2 * np.pi))
        assert tr.angles.shape == base.angles.shape
        rows = tr.angles.copy()
        rows[:, [0, 3]] /= scale
        np.testing.assert_allclose(rows, base.angles, rtol=0, atol=1e-13)


def test_a_scotch_yoke_and_an_inverted_slider_crank_keep_their_closed_forms(tmp_path: Path) -> None:
    """Scotch yoke: the yoke's reading D = -(r cos A - r cos A0), the block's C = -(r sin A - r sin A0) (1e-13),
    folds of D at -(+-r - r cos A0). Inverted slider-crank: the slide C = 2 |B0 D| - |B D| and the rocker's turn
    -D = atan2(B - D) - atan2(B0 - D) (1e-13). Rows close to 1e-12, singular values numpy's to 1e-13."""
    yoke = scotch_yoke()
    tr = lw.trace(load(tmp_path, "yoke", yoke.toml()), drive="A", until=("A", 400 * RAD), steps=24)
    a, a0 = tr.angles[:, 0], 40.0 * RAD
    np.testing.assert_allclose(tr.angles[:, 3], -(np.cos(a) - np.cos(a0)), rtol=0, atol=1e-13)
    np.testing.assert_allclose(tr.angles[:, 2], -(np.sin(a) - np.sin(a0)), rtol=0, atol=1e-13)
    closure, sigma = check_rows(yoke, tr)
    assert closure < 1e-12 and sigma < 1e-13
    by_d = lw.trace(load(tmp_path, "yoke", yoke.toml()), drive="D", branches=True)
    refs = sorted([-(1.0 - np.cos(a0)), -(-1.0 - np.cos(a0))])
    assert sorted(f.value for f in by_d.folds) == pytest.approx(refs, abs=1e-12)

    inv = inverted_slider_crank()
    for steps in (None, 36):
        tr = lw.trace(load(tmp_path, "inv", inv.toml()), drive="A", until=("A", 410 * RAD), steps=steps)
        b = np.c_[np.cos(tr.angles[:, 0]), np.sin(tr.angles[:, 0])]
        dist = np.linalg.norm(b - [3.0, 0.0], axis=1)
        np.testing.assert_allclose(tr.angles[:, 2], 2 * dist[0] - dist, rtol=0, atol=1e-13)
        psi = np.arctan2(b[:, 1], b[:, 0] - 3.0)
        assert np.abs(wrap_deg(np.degrees(tr.angles[:, 3] + psi - psi[0]))).max() < 1e-11
        closure, sigma = check_rows(inv, tr, every=4)
        assert closure < 1e-12 and sigma < 1e-13


# --------------------------------------------------------------------------------------------------- six-bars

SIX_BAR_POINTS = {
    "J1": (0.0, 0.0),
    "J2": (1.2, 2.1),
    "J3": (3.0, 0.2),
    "J4": (3.4, 2.6),
    "J5": (1.6, -1.5),
    "J6": (4.2, -1.9),
    "J7": (5.1, 1.4),
}
#: Stephenson's chain (ternary links T1 {J1, J3, J5} and T2 {J2, J4, J7} not joined) and Watt's (joined at J1).
CHAINS = {
    "stephenson": {
        "J1": ("T1", "L1"),
        "J2": ("L1", "T2"),
        "J3": ("T1", "L2"),
        "J4": ("L2", "T2"),
        "J5": ("T1", "L3"),
        "J6": ("L3", "L4"),
        "J7": ("L4", "T2"),
    },
    "watt": {
        "J1": ("T1", "T2"),
        "J2": ("T1", "L1"),
        "J3": ("L1", "L2"),
        "J4": ("L2", "T2"),
        "J5": ("T1", "L3"),
        "J6": ("L3", "L4"),
        "J7": ("L4", "T2"),
    },
}


def six_bar(chain: str, ground: str) -> Mech:
    joints = []
    for name, (b0, b1) in CHAINS[chain].items():
        bodies = ["ground" if b == ground else b for b in (b0, b1)]
        joints.append(dict(name=name, bodies=bodies, point=[*SIX_BAR_POINTS[name], 0.0]))
    return Mech(f"{chain}-{ground}", joints, planar=True)


@pytest.mark.parametrize(("chain", "drive", "target"), [("stephenson", "J3", -10.0), ("watt", "J5", -25.0)])
def test_every_inversion_of_a_six_bar_traces_the_same_rows(
    tmp_path: Path, chain: str, drive: str, target: float
) -> None:
    """Each of the six links held as the ground (Stephenson I-III and Watt I-II among them): 8 or 10 equal steps of
    the same joint give the same rows to 1e-12 rad (relative angles do not depend on the ground), every row closes
    the reference to 1e-12. Singular values: numpy's of the reference Jacobian (fundamental cycles of a
    breadth-first tree from the ground, docs/spec-format.md) to 1e-13 relative, each loop's rows in the frame of
    the loop's first body held still (a loop that does not pass through the ground, as the Watt chain's second loop
    with L1 or L3 held, has them there, not in the ground's frame: 13-21 % apart)."""
    first = None
    for ground in ("T1", "T2", "L1", "L2", "L3", "L4"):
        ref = six_bar(chain, ground)
        steps = 8 if chain == "stephenson" else 10
        tr = lw.trace(
            load(tmp_path, ref.name, ref.toml()), drive=drive, until=(drive, target * RAD), steps=steps
        )
        assert tr.branches[0].end_kind == lw.StopReason.TARGET
        closure, _ = check_rows(ref, tr)
        assert closure < 1e-12
        for row, sig in zip(tr.angles, tr.sigma, strict=True):
            s = np.linalg.svd(loop_frame_jacobian(ref, readings(ref, row)), compute_uv=False)
            assert np.abs(s[: len(sig)] - sig).max() < 1e-13 * s[0]
        if first is None:
            first = tr.angles
        np.testing.assert_allclose(tr.angles, first, rtol=0, atol=1e-12)


def test_paper_steps_landing_on_a_six_bars_crossings_find_both(tmp_path: Path) -> None:
    """Watt II six-bar whose loop A-B-C-D is a parallelogram (crank 1 at 60 deg, coupler 2, rocker 1) and whose dyad
    E-F-G lets the rocker turn fully. The crossings are at A = 180 and 360 deg; 359 equal steps of 1 deg from 60 to
    419 land on both. Both are found (A to 1e-9 deg) and the path stays on the parallelogram branch (B = -(A - 60)
    to 1e-10 deg); every 20th row closes the reference to 1e-11."""
    t = 60.0 * RAD
    pts = {
        "A": (0, 0),
        "B": (np.cos(t), np.sin(t)),
        "C": (2 + np.cos(t), np.sin(t)),
        "D": (2, 0),
        "E": (2.8, 1.9),
        "F": (4.38, 0.68),
        "G": (2.5, 0.0),
    }
    bodies = dict(
        A=("ground", "crank"),
        B=("crank", "coupler"),
        C=("coupler", "rocker"),
        D=("rocker", "ground"),
        E=("rocker", "l5"),
        F=("l5", "l6"),
        G=("l6", "ground"),
    )
    ref = Mech(
        "watt-parallelogram",
        [
            dict(name=k, bodies=list(b), point=[*pts[k], 0.0], value=60.0 if k == "A" else 0.0)
            for k, b in bodies.items()
        ],
        planar=True,
    )
    for steps in (359, 718):
        tr = lw.trace(load(tmp_path, "wp", ref.toml()), drive="A", until=("A", 419 * RAD), steps=steps)
        assert tr.branches[0].end_kind == lw.StopReason.TARGET
        found = sorted(float(np.degrees(b.angles[0])) for b in tr.bifurcations)
        assert found == pytest.approx([180.0, 360.0], abs=1e-9)
        a, b = np.degrees(tr.angles[:, 0]), np.degrees(tr.angles[:, 1])
        assert np.abs(wrap_deg(b + a - 60.0)).max() < 1e-10
        closure, _ = check_rows(ref, tr, every=20)
        assert closure < 1e-11  # 4.3e-12 on the row at the crossing of 718 steps (its residual 1.2e-15)


# ------------------------------------------------------------------------------------------ written otherwise


def hinge_lines_four_bar(turn: np.ndarray, shift: np.ndarray, scale: float = 1.0) -> str:
    pts = [np.array(p, float) for p in ([0, 0, 0], [1, 1, 0], [3.5, 3, 0], [4, 0, 0])]
    out = ['name = "tilted-four-bar"', "", "[loop]", 'convention = "hinge-lines"']
    for k, p in enumerate(pts):
        q = turn @ (p * scale) + shift
        d = turn @ np.array([0.0, 0.0, 1.0])
        out += [
            "",
            "[[loop.joints]]",
            f'name = "{"ABCD"[k]}"',
            "point = [" + ", ".join(repr(float(x)) for x in q) + "]",
            "direction = [" + ", ".join(repr(float(x)) for x in d) + "]",
        ]
    return "\n".join(out) + "\n"


def test_a_four_bar_written_with_tilted_hinge_lines_is_planar_and_traces_the_same(tmp_path: Path) -> None:
    """Axes along rot([1, 2, 3], 1.1) z, moved by (3, -2, 5); and that x1000: called planar, the same adaptive
    and paper rows as written flat (1e-13 rad)."""
    flat = load(tmp_path, "flat", hinge_lines_four_bar(np.eye(3), np.zeros(3)))
    turn, shift = rot(np.array([1.0, 2.0, 3.0]), 1.1), np.array([3.0, -2.0, 5.0])
    for name, text in (
        ("tilted", hinge_lines_four_bar(turn, shift)),
        ("tilted-x1000", hinge_lines_four_bar(turn, 1000 * shift, 1000.0)),
    ):
        mech = load(tmp_path, name, text)
        assert "planar" in repr(mech)
        for steps in (None, 36):
            a = lw.trace(flat, drive="A", until=("A", 2 * np.pi), steps=steps)
            b = lw.trace(mech, drive="A", until=("A", 2 * np.pi), steps=steps)
            assert a.angles.shape == b.angles.shape
            np.testing.assert_allclose(b.angles, a.angles, rtol=0, atol=1e-13)


def generic_7r(seed: int = 7) -> DHLoop:
    """Random ``dh`` links (d in [-0.5, 0.5], a in [0.5, 1.5], twists in [-150, 150] deg) and a closing start found
    by scipy's least squares on the audit's own ``dh`` product (to 1e-13)."""
    rng = np.random.default_rng(seed)
    links = [
        (float(rng.uniform(-0.5, 0.5)), float(rng.uniform(0.5, 1.5)), float(rng.uniform(-150, 150)))
        for _ in range(7)
    ]

    def residual(theta: np.ndarray) -> np.ndarray:
        g = np.eye(4)
        for t, (d, a, al) in zip(theta, links, strict=True):
            g = g @ dh(t, d, a, al * RAD)
        return (g - np.eye(4))[:3].ravel()

    for _ in range(50):
        fit = least_squares(residual, rng.uniform(-np.pi, np.pi, 7), xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if np.abs(fit.fun).max() < 1e-13:
            return DHLoop("generic-7r", links, list(np.degrees(fit.x)))
    raise AssertionError("no closing start found")


def test_a_generic_7r_against_the_audits_dh_product(tmp_path: Path) -> None:
    """Every 5th row closes the audit's ``dh`` product to 1e-12, its singular values are numpy's of the audit's
    Jacobian to 1e-13 relative; every fold is where the drive A has an extreme among the rows around it (and every
    extreme of the rows is a fold); the path closes with its last row equal to its first (1e-12)."""
    loop = generic_7r()
    tr = lw.trace(load(tmp_path, "7r", loop.toml()), max_steps=3000)
    rows = np.degrees(tr.angles)
    for i in range(0, len(rows), 5):
        assert loop.closure(rows[i]) < 1e-12
        s = np.linalg.svd(loop.jacobian(rows[i]), compute_uv=False)
        assert np.abs(s[: tr.sigma.shape[1]] - tr.sigma[i]).max() < 1e-13 * s[0]
    a = tr.angles[:, 0]
    turns = np.where(np.sign(np.diff(a)[1:]) != np.sign(np.diff(a)[:-1]))[0] + 1
    assert len(tr.folds) == len(turns) > 0
    for fold, k in zip(sorted(tr.folds, key=lambda f: f.step), turns, strict=True):
        assert abs(fold.step - k) <= 1
        neighbours = a[max(k - 1, 0) : k + 2]
        assert fold.value >= neighbours.max() - 1e-12 or fold.value <= neighbours.min() + 1e-12
    assert tr.branches[0].end_kind == lw.StopReason.CLOSED
    np.testing.assert_allclose(tr.angles[-1], tr.angles[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.sigma[-1], tr.sigma[0], rtol=0, atol=1e-12)
    assert tr.residual[-1] == tr.residual[0]


def test_a_coupled_bricard_loop_has_the_singular_values_of_its_added_columns(tmp_path: Path) -> None:
    """The built-in line-symmetric Bricard with new dimensions written out as hinge lines, with couple = [[A, D],
    [B, E], [C, F]]: three singular values, numpy's of the reference Jacobian whose coupled columns add (1e-13
    relative); the rows close the reference to 1e-12 and, in paper mode, equal the uncoupled loop's (1e-11)."""
    import tomllib

    from linkwork.io.spec import dump_spec

    built = lw.load(
        "bricard-line", a1=0.8, a2=1.1, a3=1.3, alpha1=-30 * RAD, alpha2=70 * RAD, alpha3=140 * RAD, d1=-0.2,
        d2=0.4, d3=0.1, theta=75 * RAD,
    )  # fmt: skip
    text = dump_spec(built)
    lines = tomllib.loads(text)["loop"]["joints"]
    ref = Mech(
        "bricard",
        [
            dict(
                name=j["name"],
                bodies=[f"L{i}" if i else "ground", f"L{(i + 1) % 6}" if (i + 1) % 6 else "ground"],
                point=j["point"],
                direction=j["direction"],
                value=j["theta"],
            )
            for i, j in enumerate(lines)
        ],
        planar=False,
    )
    couples = [["A", "D"], ["B", "E"], ["C", "F"]]
    coupled = load(
        tmp_path,
        "coupled",
        text.replace(
            'convention = "hinge-lines"', f'convention = "hinge-lines"\ncouple = {couples}'.replace("'", '"')
        ),
    )
    free = load(tmp_path, "free", text)
    a = lw.trace(free, drive="A", until=("A", 375 * RAD), steps=30)
    b = lw.trace(coupled, drive="A", until=("A", 375 * RAD), steps=30)
    assert b.sigma.shape[1] == 3
    np.testing.assert_allclose(b.angles, a.angles, rtol=0, atol=1e-11)
    for row, sig in zip(b.angles, b.sigma, strict=True):
        r = readings(ref, row)
        assert ref.poses(r)[1] < 1e-12
        s = np.linalg.svd(ref.jacobian(r, columns=couples), compute_uv=False)
        assert np.abs(s[:3] - sig).max() < 1e-13 * s[0]


# --------------------------------------------------------------------------------------------------- exports

EXPORTED: dict[str, Callable[[], Mech]] = {
    "trammel": trammel,
    "scotch-yoke": scotch_yoke,
    "inverted-slider-crank": inverted_slider_crank,
    "stephenson-L3": lambda: six_bar("stephenson", "L3"),
    "watt-L1": lambda: six_bar("watt", "L1"),
}


@pytest.mark.parametrize("name", sorted(EXPORTED))
def test_mjcf_welds_close_along_the_trace(tmp_path: Path, name: str) -> None:
    """MuJoCo (``mj_forward``'s equality residuals ``efc_pos``) sees every loop-closing weld of the exported model
    closed to 1e-11 at every 5th of 40 traced rows (joint qpos = the trace's value - the start value)."""
    mujoco = pytest.importorskip("mujoco")
    from linkwork.export.mjcf import mjcf

    ref = EXPORTED[name]()
    mech = load(tmp_path, name, ref.toml())
    tr = lw.trace(mech, max_steps=40, max_step=5 * RAD)
    model = mujoco.MjModel.from_xml_string(mjcf(mech))
    data = mujoco.MjData(model)
    address = [model.jnt_qposadr[model.joint(n).id] for n in mech.joint_names]
    for q in (tr.angles - mech.offsets)[::5]:
        data.qpos[address] = q
        mujoco.mj_forward(model, data)
        residual = data.efc_pos[data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
        assert len(residual) > 0 and np.abs(residual).max() < 1e-11


# ----------------------------------------------------------------------------------------- an eight-bar (3 loops)

#: Theo Jansen's "holy numbers" (a ... m): ground pivots O (crank) and A = (-a, -l); crank m.
JANSEN = dict(
    a=38.0, b=41.5, c=39.3, d=40.1, e=55.8, f=39.4, g=36.7, h=65.7, i=49.0, j=50.0, k=61.9, l=7.8, m=15.0
)


def jansen_points(theta: float) -> dict[str, np.ndarray]:
    """Every pivot and the foot F of Jansen's leg at crank angle ``theta`` (radians), by circle intersections in
    the leg's usual assembly (B above, C below, D, E outside, F the lowest)."""
    from audit_reference import circles

    p = JANSEN
    a_, m_ = (
        np.array([-p["a"], -p["l"], 0.0]),
        np.array([p["m"] * np.cos(theta), p["m"] * np.sin(theta), 0.0]),
    )

    def meet(
        c1: np.ndarray, r1: float, c2: np.ndarray, r2: float, key: Callable[[np.ndarray], float]
    ) -> np.ndarray:
        return min((np.r_[x, 0.0] for x in circles(c1, r1, c2, r2)), key=key)

    b = meet(m_, p["j"], a_, p["b"], lambda x: -x[1])
    c = meet(m_, p["k"], a_, p["c"], lambda x: x[1])
    d = meet(a_, p["d"], b, p["e"], lambda x: x[0])
    e = meet(d, p["f"], c, p["g"], lambda x: x[0])
    f = meet(e, p["h"], c, p["i"], lambda x: x[1])
    return dict(O=np.zeros(3), M=m_, A=a_, B=b, C=c, D=d, E=e, F=f)


def test_jansens_leg_draws_its_foot_curve(tmp_path: Path) -> None:
    """Jansen's leg as a planar [mechanism] (8 bodies, 10 revolute joints, 3 loops) with its foot as a named point:
    a full crank turn adaptive and in 36 and 360 equal steps. Every row closes the reference to 1e-11 (lengths of
    about 60), its singular values are numpy's to 1e-13 relative, and the foot in ``positions`` is the circle
    intersections' foot to 1e-10."""
    from linkwork.kinematics.points import positions

    start = jansen_points(30 * RAD)
    joints = [
        ("O", ["ground", "crank"], "O"),
        ("M1", ["crank", "lj"], "M"),
        ("M2", ["crank", "lk"], "M"),
        ("B", ["lj", "tri1"], "B"),
        ("A1", ["tri1", "ground"], "A"),
        ("C1", ["lk", "lc"], "C"),
        ("A2", ["lc", "ground"], "A"),
        ("D", ["tri1", "lf"], "D"),
        ("E", ["lf", "tri2"], "E"),
        ("C2", ["tri2", "lc"], "C"),
    ]
    ref = Mech(
        "jansen",
        [dict(name=n, bodies=b, point=list(start[p]), value=30.0 if n == "O" else 0.0) for n, b, p in joints],
        planar=True,
    )
    foot = start["F"]
    text = (
        ref.toml()
        + f'\n[[points]]\nname = "foot"\nbody = "tri2"\nposition = [{float(foot[0])!r}, {float(foot[1])!r}, 0.0]\n'
    )
    mech = load(tmp_path, "jansen", text)
    for steps in (None, 36, 360):
        tr = lw.trace(mech, drive="O", until=("O", 390 * RAD), steps=steps)
        assert tr.branches[0].end_kind == lw.StopReason.TARGET
        closure, sigma = check_rows(ref, tr, every=6)
        assert closure < 1e-11 and sigma < 1e-13
        _, points = positions(mech, tr.angles)
        feet = np.array([jansen_points(t)["F"] for t in tr.angles[:, 0]])
        assert np.abs(points[:, 0, :2] - feet[:, :2]).max() < 1e-10
