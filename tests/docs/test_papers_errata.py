"""The errata of docs/papers.md, checked: the paper's own printed numbers against its own equations, and
linkwork's procedures against the corrected reading (each claim of the page has its test here)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from linkwork.synthesis.arc_segment import arc_points, fit_arc_segment
from linkwork.synthesis.segment_matrix import design_vectors
from linkwork.synthesis.targets import mean_piece_length, target_profile

#: Sec. 2 of Shamsudin et al. 2013, as printed.
ARC = (26.1738, 31.0847, 34.4737)
TARGET = (26.1669, 31.0760, 34.4562)
S_D = 0.35


def _mean(counts: tuple[int, ...]) -> float:
    targets = tuple(SimpleNamespace(length=s, pieces=m) for s, m in zip(TARGET, counts, strict=True))
    return mean_piece_length(targets)  # type: ignore[arg-type]  # Eq. 7 needs only length and pieces


def test_printed_mean_piece_length_belongs_to_75_89_98_pieces() -> None:
    assert _mean((76, 90, 99)) == pytest.approx(0.3460, abs=5e-5)  # what the printed counts give
    assert _mean((75, 89, 98)) == pytest.approx(0.3499, abs=1e-4)  # the printed 0.3499
    assert [int(np.ceil(c / S_D)) for c in ARC] == [
        75,
        89,
        99,
    ]  # Eq. 3: the procedure only goes down from here


def test_fixed_end_counts_cannot_be_75_89_98() -> None:
    counts = [target_profile([[0.0, 0.0], [c, 0.0]], S_D).pieces for c in (12.24, 12.90, 14.13)]
    assert counts == [35, 37, 40]
    assert 12.24 / 75 < 0.5 * S_D  # 75 pieces on 12.24 would be less than half the desired length each


def test_eq_20_needs_its_one_over_p_and_eq_18_its_count() -> None:
    s, kappa, counts = 0.1, 0.8, (8, 10, 13)
    pieces = [arc_points(kappa, s, m) for m in counts]
    printed_eq20 = sum(np.linalg.norm(np.diff(z, axis=0), axis=1).mean() for z in pieces)
    assert printed_eq20 == pytest.approx(3 * s, rel=1e-12)  # p times the piece length
    fit = fit_arc_segment(pieces)
    assert fit.piece_length == pytest.approx(s, rel=1e-12)
    assert fit.curvature == pytest.approx(kappa, rel=1e-9)
    np.testing.assert_allclose(fit.errors, 0.0, atol=1e-9)  # the arcs are reproduced exactly
    # Eq. 18 as printed: sum of the sum(m_j - 1) interior radii over sum(m_j) - 1
    r = 1.0 / kappa
    printed_eq18 = sum((m - 1) * r for m in counts) / (sum(counts) - 1)
    assert printed_eq18 == pytest.approx(r * (sum(counts) - 3) / (sum(counts) - 1), rel=1e-12)
    assert printed_eq18 < 0.94 * r


def test_there_are_two_to_the_q_minus_one_design_vectors_with_a_c() -> None:
    for q in range(1, 7):
        with_c = design_vectors(q, [10, 12])  # different piece counts: all-M is left out
        assert len(with_c) == 2**q - 1 and all("C" in v for v in with_c)
        assert len(design_vectors(q, [10, 10])) == 2**q
    assert 2 ** (4 - 1) == 8 != len(design_vectors(4, [10, 12])) == 15
