"""Target profiles (Sec. 2) against counts and lengths worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.errors import SpecError
from linkwork.synthesis.problem import Problem
from linkwork.synthesis.targets import arc_length, mean_piece_length, target_profile, target_profiles


def test_straight_line_piece_count_by_hand() -> None:
    # C = 1, s_d = 0.3: ceil(3.33) = 4 pieces (|0.3 - 0.25| = 0.05), 3 pieces (|0.3 - 1/3| = 0.033) is closer,
    # 2 pieces (|0.3 - 0.5| = 0.2) is worse: 3 pieces at 0, 1/3, 2/3, 1.
    t = target_profile([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]], 0.3)
    assert t.pieces == 3
    assert t.arc_length == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(t.points[:, 0], [0.0, 1 / 3, 2 / 3, 1.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(t.points[:, 1], 0.0, rtol=0, atol=0)
    assert t.target_length == pytest.approx(1 / 3, abs=1e-15)


def test_corner_polyline_keeps_seven_pieces() -> None:
    # (0,0)-(3,0)-(3,4): C = 7, s_d = 1 gives 7 unit chords (the corner is a station); 6 pieces would cut the
    # corner (mean chord (5 * 7/6 + 5/6) / 6 = 1.111, error 0.111 > 0), so 7 stays.
    t = target_profile([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]], 1.0)
    assert t.arc_length == pytest.approx(7.0, abs=1e-14)
    assert t.pieces == 7
    assert t.target_length == pytest.approx(1.0, abs=1e-14)
    assert t.length == pytest.approx(7.0, abs=1e-14)


def test_closed_profile_repeats_its_first_point() -> None:
    square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]  # closing edge added for a closed profile
    t = target_profile(square, 0.5, closed=True)
    assert t.arc_length == pytest.approx(4.0, abs=1e-15)
    assert t.pieces == 8
    np.testing.assert_array_equal(t.points[0], t.points[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(t.points, axis=0), axis=1), 0.5, rtol=0, atol=1e-15)


def test_mean_piece_length_eq7_by_hand() -> None:
    lines = (np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 0.0], [0.0, 2.0]]))
    targets = target_profiles(Problem(profiles=lines, piece_length=0.3, design="C"))
    # 1 -> 3 pieces of 1/3; 2 -> ceil(6.67) = 7 (|0.3 - 0.2857| = 0.014), 6 (|0.3 - 0.333| = 0.033) is worse
    assert [t.pieces for t in targets] == [3, 7]
    assert mean_piece_length(targets) == pytest.approx(3.0 / 10.0, abs=1e-15)  # Eq. (7): (1 + 2) / (3 + 7)


def test_arc_length_of_polyline() -> None:
    assert arc_length([[0, 0], [3, 4], [3, 5]]) == pytest.approx(6.0, abs=1e-15)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_bad_piece_length_is_a_spec_error(bad: float) -> None:
    with pytest.raises(SpecError, match="piece_length"):
        target_profile([[0, 0], [1, 0]], bad)
