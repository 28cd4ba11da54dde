"""What a trace keeps on a mechanism (its flattened loops, the start's SVD and rank, the dyad plan, ...) can never
be served stale: a changed mechanism is a new object with nothing kept, its arrays and the kept ones cannot be
written, copies and unpickled mechanisms start afresh and frozen; and the compiled passes the closed-form trace
uses give exactly what numpy gives."""

from __future__ import annotations

import copy
import pickle
from dataclasses import fields, is_dataclass, replace
from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics import closure, kernels
from linkwork.kinematics.jit import select_backend
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import DEFAULT, Tolerances, all_full_rank, numerical_rank, numerical_ranks
from linkwork.kinematics.trace_result import Trace
from linkwork.kinematics.tracer import start_point

WATT = Path(__file__).resolve().parents[2] / "examples" / "specs" / "watt-six-bar.toml"


@pytest.fixture(autouse=True)
def compiled(monkeypatch: pytest.MonkeyPatch) -> None:
    """The compiled kernels, so that planar paper-mode traces take the closed form."""
    monkeypatch.setenv("LINKWORK_JIT", "compiled")


def turn(mech: Mechanism, steps: int = 90) -> Trace:
    """One full turn of the crank ``A`` in ``steps`` equal steps (the closed-form path of a planar linkage)."""
    return lw.trace(mech, until=("A", float(mech.offsets[mech.index("A")]) + 2.0 * np.pi), steps=steps)


def assert_same(a: Trace, b: Trace) -> None:
    """Two traces with the same rows, bit for bit."""
    for name in ("angles", "sigma", "residual", "branch", "step", "arclength", "test", "rank"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y), name
    assert [br.end_reason for br in a.branches] == [br.end_reason for br in b.branches]
    assert a.stats.max_misfit == b.stats.max_misfit


def reference_start(mech: Mechanism) -> tuple[float, np.ndarray]:
    """Residual norm and singular values at the reference from the numpy closure (not the kernels)."""
    residual = float(np.linalg.norm(closure.closure_residual(mech, np.zeros(mech.n_joints))))
    jac = closure.reduce(mech, closure.jacobian(mech, np.zeros(mech.n_joints)))
    return residual, np.linalg.svd(jac, compute_uv=False)


def test_a_mechanism_changed_by_replace_is_traced_afresh() -> None:
    """Two four-bars that differ in one length: the second made from the first (already traced, so that all it
    keeps is filled) by ``dataclasses.replace`` traces as a freshly loaded one does, and the start it keeps is
    its own (against the numpy closure)."""
    first = lw.load("four-bar")
    other = lw.load("four-bar", coupler=2.7)
    turn(first)
    changed = replace(first, twists=other.twists, offsets=other.offsets, hinge_points=other.hinge_points)
    assert_same(turn(changed), turn(lw.load("four-bar", coupler=2.7)))
    assert not np.array_equal(turn(changed).angles, turn(first).angles)
    backend = select_backend()
    for mech in (first, changed):
        r0, _, s0, _ = start_point(mech, backend)
        residual, sigma = reference_start(mech)
        assert r0 < 1e-12 and residual < 1e-12
        np.testing.assert_allclose(s0, sigma, rtol=0.0, atol=1e-13 * float(sigma[0]))
    assert not np.allclose(start_point(first, backend)[2], start_point(changed, backend)[2])


def test_couplings_and_a_new_reference_make_new_mechanisms_with_their_own_values() -> None:
    """``with_couplings`` and ``with_reference`` of a traced mechanism: their unknowns, flattened arrays, first
    joints and start are their own."""
    mech = lw.load("bennett")
    lw.trace(mech, max_steps=20)
    coupled = mech.with_couplings([["A", "C"]])
    assert (mech.n_unknowns, coupled.n_unknowns) == (4, 3)
    assert coupled.kernel_arrays[5].tolist() == [0, 1, 0, 2] and mech.kernel_arrays[5].tolist() == [
        0,
        1,
        2,
        3,
    ]
    assert coupled.first_joints == (0, 1, 3) and mech.first_joints == (0, 1, 2, 3)
    path = lw.trace(mech, until=("A", float(mech.offsets[0]) + 0.4))
    moved = mech.with_reference(mech.q_from_angles(path.angles[-1]))
    r0, _, s0, _ = start_point(moved, select_backend())
    residual, sigma = reference_start(moved)
    assert r0 < 1e-10 and residual < 1e-10
    np.testing.assert_allclose(s0, sigma, rtol=0.0, atol=1e-12 * float(sigma[0]))
    np.testing.assert_allclose(s0, path.sigma[-1], rtol=0.0, atol=1e-12 * float(sigma[0]))


def kept_arrays(value: object) -> list[np.ndarray]:
    """Every array in a kept value (tuples, lists and dataclasses opened)."""
    if isinstance(value, np.ndarray):
        return [value]
    if isinstance(value, tuple | list):
        return [a for v in value for a in kept_arrays(v)]
    if is_dataclass(value):
        return [a for f in fields(value) for a in kept_arrays(getattr(value, f.name))]
    return []


def test_nothing_kept_can_be_written() -> None:
    """The mechanism's arrays and every array a trace keeps on it (closed form, predictor-corrector, limits)
    are read-only."""
    mech = lw.load("four-bar")
    turn(mech)
    lw.trace(mech, limits={"A": (0.0, 3.0)}, until=("A", 2.0))
    lw.trace(mech, max_steps=30)
    kept = [mech.twists, mech.offsets, mech.groups, mech.hinge_points, *mech.kernel_arrays]
    derived = vars(mech)["_derived"]
    assert len(derived) >= 5  # the start, its rank, the dyad plan, the unbounded limits, which unknowns turn
    kept += kept_arrays(list(derived.values()))
    assert len(kept) > 20
    for array in kept:
        assert not array.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 1


@pytest.mark.parametrize("clone", [copy.copy, copy.deepcopy, lambda m: pickle.loads(pickle.dumps(m))])
def test_copies_start_without_kept_values_and_frozen(clone: object) -> None:
    """A copy or an unpickled mechanism (numpy unpickles arrays writable) keeps nothing of the original's derived
    values, has read-only arrays again, and traces as the original."""
    mech = lw.load(str(WATT))
    before = turn(mech)
    twin = clone(mech)  # type: ignore[operator]
    assert twin is not mech and twin.twists is not mech.twists
    assert "_derived" not in vars(twin) and "kernel_arrays" not in vars(twin)
    for array in (twin.twists, twin.offsets, twin.groups, twin.hinge_points):
        assert not array.flags.writeable
    assert_same(turn(twin), before)


def test_joint_values_kernel_is_numpy_gather_and_add() -> None:
    """``kernels.joint_values`` against ``u[:, groups] + offsets``, bit for bit: every joint its own unknown,
    a permutation, and coupled joints sharing an unknown."""
    rng = np.random.default_rng(3)
    for groups in ([0, 1, 2, 3], [2, 0, 3, 1], [0, 1, 0, 2, 1]):
        g = np.array(groups, dtype=np.int64)
        u = rng.normal(size=(257, int(g.max()) + 1)) * 10.0
        offsets = rng.normal(size=len(g))
        out = np.empty((len(u), len(g)))
        kernels.joint_values(u, g, offsets, out)
        assert np.array_equal(out, u[:, g] + offsets)


def full_by_rows(sigma: np.ndarray, tol: Tolerances) -> bool:
    """Every row of full rank, row by row with :func:`numerical_rank` (the definition)."""
    return all(numerical_rank(row, tol) == sigma.shape[1] for row in sigma)


def test_full_rank_checks_agree_with_numerical_rank_row_by_row() -> None:
    """The compiled and numpy full-rank checks (every ratio above ``loose``: a sufficient test, exact at the
    boundary), and ``numerical_ranks``, against ``numerical_rank`` of each row: generic rows, one ratio just
    above, at and just below ``loose``, a zero, NaN and infinite values, a negative row, unsorted rows, a floor
    above ``loose``."""
    rng = np.random.default_rng(11)
    base = np.sort(rng.uniform(0.5, 2.0, size=(50, 3)), axis=1)[:, ::-1].copy()
    for tol in (DEFAULT, Tolerances(floor=1e-6, loose=1e-4, min_gap=10.0)):
        cases = {"generic": base, "unsorted": base[:, ::-1].copy()}
        loose = tol.loose
        for name, value in {
            "above loose": np.nextafter(loose, 1.0),
            "at loose": loose,
            "below loose": np.nextafter(loose, 0.0),
            "zero": 0.0,
            "nan": np.nan,
        }.items():
            s = base.copy()
            s[7] = (1.0, 0.5, value)  # the ratio is the value itself
            cases[name] = s
        s = base.copy()
        s[4, 0] = np.inf
        cases["infinite first"] = s
        s = base.copy()
        s[9] = -s[9]
        cases["negative"] = s
        for name, s in cases.items():
            quick = all_full_rank(s, tol)
            assert bool(kernels.every_row_full_rank(s, tol.loose)) == quick, name
            if quick:  # a sufficient test: where it fails, numerical_ranks decides row by row
                assert full_by_rows(s, tol), name
            assert quick == (name in ("generic", "above loose", "unsorted")), name
            with np.errstate(invalid="ignore"):  # inf / inf in numpy's ratios
                expected = [numerical_rank(row, tol) for row in s]
                assert numerical_ranks(s, tol).tolist() == expected, name
            assert numerical_ranks(s, tol, compiled=True).tolist() == expected, name
    assert not all_full_rank(
        base, Tolerances(floor=1e-3, loose=1e-4)
    )  # a floor above loose: the general path


def test_compiled_rank_counts_with_gap_tests() -> None:
    """``numerical_ranks`` with the compiled counts, on rows whose smallest values fall between ``floor`` and
    ``loose`` (the gap test decides them), against ``numerical_rank`` row by row and the numpy counts."""
    rng = np.random.default_rng(5)
    s = np.sort(rng.uniform(0.5, 2.0, size=(400, 6)), axis=1)[:, ::-1].copy()
    s[:, -1] *= 10.0 ** rng.uniform(-17.0, 0.0, size=400)  # from round-off to not small
    s[::7, -2] *= 1e-7  # two small values in some rows
    s[::50] = 0.0
    s = np.sort(s, axis=1)[:, ::-1].copy()
    expected = [numerical_rank(row) for row in s]
    assert len(set(expected)) >= 3  # ranks 0, 4, 5 and 6 occur
    assert numerical_ranks(s, compiled=True).tolist() == expected
    assert numerical_ranks(s).tolist() == expected


@pytest.mark.parametrize("name", ["four-bar", "slider-crank", "watt"])
def test_the_closed_form_trace_reports_what_the_marcher_would(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The closed form's Trace is built without a marcher: its branch, stats and events are those of the same
    trace by the predictor-corrector (the closed form switched off), field by field."""
    from linkwork.kinematics import tracer

    mech = lw.load(str(WATT) if name == "watt" else name)
    fast = turn(mech, 180)
    monkeypatch.setattr(tracer, "closed_form_rows", lambda *args, **kwargs: None)
    general = turn(mech, 180)
    assert fast.drive == general.drive and fast.bifurcations == general.bifurcations == ()
    assert fast.folds == general.folds == ()
    (a,), (b,) = fast.branches, general.branches
    assert a.end_value is not None and b.end_value is not None
    assert abs(a.end_value - b.end_value) < 1e-12
    assert replace(a, end_value=None) == replace(b, end_value=None)
    same = ("start_rank", "start_mobility", "mode", "closure_tol", "sign_changes_without_rank_drop")
    same += ("branches_not_retraced", "has_target", "unmet", "points")
    assert [getattr(fast.stats, k) for k in same] == [getattr(general.stats, k) for k in same]
    assert fast.stats.max_misfit == float(np.max(fast.residual)) and general.stats.max_misfit < 1e-12
    assert np.array_equal(fast.rank, general.rank) and np.array_equal(fast.step, general.step)
    for array in (fast.angles, fast.sigma, fast.residual, fast.rank, fast.step, fast.branch, fast.test):
        assert array.flags.c_contiguous and array.flags.writeable


def test_the_kept_path_start_is_per_backend_and_tolerances_and_refusals_are_not_kept() -> None:
    """What a trace keeps of its start (path rank, null vector, range basis) is the start's, by a fresh numpy SVD
    of the numpy closure Jacobian; it is kept per tolerances: tolerances that see the start's smallest singular
    value as zero refuse the start (mobility 2) on every call, after and before traces with the defaults (kept
    under their own key, as a module constant)."""
    mech = lw.load("four-bar")
    turn(mech)
    _, sigma = reference_start(mech)
    jac = closure.reduce(mech, closure.jacobian(mech, np.zeros(mech.n_joints)))
    starts = [v for k, v in vars(mech)["_derived"].items() if isinstance(k, tuple) and k[0] == "path start"]
    assert len(starts) == 1
    (start,) = starts
    assert start.r_path == numerical_rank(sigma) == 3 and start.n_sigma == len(sigma)
    assert abs(float(np.linalg.norm(start.tangent)) - 1.0) < 1e-14
    assert float(np.max(np.abs(jac @ start.tangent))) < 1e-13 * float(sigma[0])
    np.testing.assert_allclose(start.basis.T @ start.basis, np.eye(3), rtol=0.0, atol=1e-14)
    between = float(sigma[1] + sigma[2]) / (2.0 * float(sigma[0]))  # (0.27: zero below this, non-zero above)
    blind = replace(DEFAULT, floor=between, loose=between)
    for _ in range(2):
        with pytest.raises(lw.LinkworkError, match="mobility 2"):
            turn_with(mech, blind)
        assert_same(turn(mech), turn(lw.load("four-bar")))
    assert_same(
        turn_with(mech, DEFAULT.with_closure(1e-6)),
        turn_with(lw.load("four-bar"), DEFAULT.with_closure(1e-6)),
    )
    keys = [k for k in vars(mech)["_derived"] if isinstance(k, tuple) and k[0] == "path start"]
    assert sorted(keys, key=len) == [("path start", True), ("path start", True, DEFAULT.with_closure(1e-6))]


def turn_with(mech: Mechanism, tol: Tolerances) -> Trace:
    """:func:`turn` with the tolerances ``tol``."""
    return lw.trace(mech, until=("A", float(mech.offsets[mech.index("A")]) + 2.0 * np.pi), steps=90, tol=tol)
