"""Segment-matrix constraints (Secs. 3.1, 3.2, 4) as properties of the initial matrices and the adjustment."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from linkwork.errors import SpecError
from linkwork.synthesis.segment_matrix import (
    adjust,
    check_design,
    check_feasible,
    design_vectors,
    initial_segment_matrices,
    is_valid,
    search_segment_matrix,
)


def assert_constraints(sm: np.ndarray, design: str, pieces: list[int], alpha: int) -> None:
    assert sm.shape == (len(design), len(pieces))
    np.testing.assert_array_equal(sm.sum(axis=0), pieces)  # exact integers: each column sums to m_j
    assert sm.min() >= alpha
    for e, kind in enumerate(design):
        if kind == "M":
            assert np.all(sm[e] == sm[e, 0]), f"M-segment row {e} differs across profiles: {sm[e]}"


problems = st.tuples(
    st.text(alphabet="MC", min_size=1, max_size=6).filter(lambda d: "C" in d),
    st.integers(1, 6),
    st.lists(st.integers(0, 80), min_size=1, max_size=4),
    st.integers(0, 2**32 - 1),
)


@settings(max_examples=150, deadline=None)
@given(problems)
def test_initial_matrices_and_adjustments_keep_every_constraint(
    case: tuple[str, int, list[int], int],
) -> None:
    design, alpha, extra, seed = case
    rng = np.random.default_rng(seed)
    pieces = [len(design) * alpha + x for x in extra]
    for sm in initial_segment_matrices(design, pieces, alpha, 4, rng):
        assert_constraints(sm, design, pieces, alpha)
        for _ in range(5):
            em = rng.uniform(0.0, 1.0, size=sm.shape)
            sm = adjust(sm, em, design, alpha)
            assert_constraints(sm, design, pieces, alpha)
            assert is_valid(sm, design, pieces, alpha)


def test_adjustment_rules_of_section_4_by_hand() -> None:
    # design MCC, alpha 2; E_bar = 0.5. M-row mean 0.2 < E_bar: +1 everywhere. C row 1: 0.1 < 0.5 -> +1 on
    # profile 1, 0.9 > 0.5 -> -1 on profile 2. The last C-segment keeps the column sums: -2 and 0.
    sm = np.array([[5, 5], [6, 9], [9, 10]])
    em = np.array([[0.2, 0.2], [0.1, 0.9], [0.7, 0.9]])
    np.testing.assert_array_equal(adjust(sm, em, "MCC", 2), [[6, 6], [7, 8], [7, 10]])


def test_last_c_segment_never_drops_below_the_minimum() -> None:
    # every other segment wants to grow, but the last C-segment already has alpha pieces
    sm = np.array([[4, 4], [4, 6], [3, 3]])
    em = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    out = adjust(sm, em, "MCC", 3)
    assert_constraints(out, "MCC", [11, 13], 3)


def test_design_vectors_all_m_only_for_equal_counts() -> None:
    assert len(design_vectors(5, [127, 149, 155])) == 2**5 - 1
    assert len(design_vectors(5, [100, 100])) == 2**5
    assert "MMMMM" not in design_vectors(5, [127, 149, 155])


def test_search_keeps_the_best_matrix_of_the_whole_history() -> None:
    rng = np.random.default_rng(4)
    pieces = [30, 40]
    table: dict[tuple[int, ...], np.ndarray] = {}

    def errors(sm: np.ndarray) -> np.ndarray:
        key = tuple(sm.ravel())
        if key not in table:
            table[key] = rng.uniform(size=sm.shape)
        return table[key]

    starts = initial_segment_matrices("MCC", pieces, 3, 3, rng)
    out = search_segment_matrix("MCC", starts, errors, 3)
    seen = min(float(em.max()) for em in table.values())
    assert float(out.error_matrix.max()) == seen  # exact: the same stored value
    assert sum(len(h) for h in out.history) == out.iterations
    for trail in out.history:  # the stopping rule: the last value is >= each of the five before it
        assert len(trail) <= 6 or trail[-1] >= max(trail[-6:-1])


def test_infeasible_problems_are_spec_errors() -> None:
    with pytest.raises(SpecError, match="min_pieces"):
        check_feasible("MCC", [10, 12], 4)
    with pytest.raises(SpecError, match="no C-segment"):
        check_feasible("MM", [10, 12], 2)
    with pytest.raises(SpecError, match="design"):
        check_design("MXC")


# The paper's printed example (Shamsudin et al. 2013, Eqs. 11, 25, 27): V = [M C M C], alpha = 5,
# m* = 76, 90, 99. Printed p x q (a row per profile); linkwork holds q x p, hence the transposes.
SM1 = np.array([[15, 13, 9, 39], [15, 9, 9, 57], [15, 39, 9, 36]])
EM1 = np.array([[0.10, 0.32, 0.04, 0.43], [0.15, 0.19, 0.03, 1.37], [0.19, 0.46, 0.06, 1.50]])
SMF = np.array([[19, 12, 14, 31], [19, 22, 14, 35], [19, 42, 14, 24]])


def test_paper_sm1_em1_metrics_as_printed() -> None:
    assert is_valid(SM1.T, "MCMC", [76, 90, 99], 5) and is_valid(SMF.T, "MCMC", [76, 90, 99], 5)
    assert EM1.max() == 1.50  # "E_max = 1.50" (Eq. 22)
    assert round(EM1.mean(), 2) == 0.40  # "E_bar = 0.40" (Eq. 24)
    assert (
        round(EM1[:, 0].mean(), 2) == 0.15 and round(EM1[:, 2].mean(), 2) == 0.04
    )  # E_bar^1, E_bar^3 (Eq. 23)


def test_paper_sm1_through_one_adjustment() -> None:
    # Sec. 4 by hand on the printed EM1 (E_bar = 4.84 / 12 = 0.403): both M-segments have E_bar^e < E_bar
    # -> +1 on every profile; C-segment 2: 0.32, 0.19 < E_bar -> +1, 0.46 > E_bar -> -1; the last C-segment
    # keeps each profile's total (Eq. 26): 39 - 3, 57 - 3, 36 - 1.
    expected = np.array([[16, 14, 10, 36], [16, 10, 10, 54], [16, 38, 10, 35]])
    out = adjust(SM1.T, EM1.T, "MCMC", 5)
    np.testing.assert_array_equal(out.T, expected)
    assert is_valid(out, "MCMC", [76, 90, 99], 5)
