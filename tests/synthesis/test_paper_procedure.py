"""The paper's procedure, replayable: a given initial segment matrix (Eq. 11), Eq. 34's joint ranges on the
targets and on the chain (``merge_on``), and the problem-file keys that set them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import save_profile
from linkwork.synthesis import Problem, synthesize
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.targets import target_profiles


def polygon_arc(radius: float, piece: float, pieces: int) -> np.ndarray:
    """Vertices of a regular polygon on a circle: equal pieces of length ``piece``, each turning by phi."""
    phi = 2.0 * math.asin(piece / (2.0 * radius))
    k = np.arange(pieces + 1) * phi
    return radius * np.column_stack([np.sin(k), 1.0 - np.cos(k)])


ARCS = ((1.0, 30), (1.5, 40), (2.0, 50))


def arcs_problem(**kw: object) -> Problem:
    profiles = tuple(polygon_arc(r, 0.1, m) for r, m in ARCS)
    settings: dict[str, object] = {"piece_length": 0.1, "min_pieces": 4, "design": "CCC", "starts": 2}
    settings.update(kw)
    return Problem(profiles=profiles, **settings)  # type: ignore[arg-type]


def test_target_profiles_of_polygon_arcs_are_their_vertices() -> None:
    for (r, m), target in zip(ARCS, target_profiles(arcs_problem()), strict=True):
        assert target.pieces == m
        np.testing.assert_allclose(target.points, polygon_arc(r, 0.1, m), rtol=0, atol=1e-12)


def test_joint_ranges_on_the_targets_are_the_turning_angles() -> None:
    # on a regular polygon every vertex turns by phi = 2 asin(s / 2r): sigma_j = phi_j at any segmentation
    # point, so Eq. 34's range on the targets is phi(r = 1) - phi(r = 2) for every joint
    expected = 2.0 * math.asin(0.05) - 2.0 * math.asin(0.025)
    result = synthesize(arcs_problem(merge_below=math.radians(179.0)))
    comp = result.compound
    assert comp is not None and comp.target_ranges is not None and comp.target_angles is not None
    np.testing.assert_allclose(comp.target_ranges, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.ptp(comp.joint_angles, axis=1), comp.joint_ranges, rtol=0, atol=1e-15)
    ranges = result.to_dict()["compound"]["ranges"]
    np.testing.assert_allclose(ranges["targets"], math.degrees(expected), rtol=0, atol=1e-7)
    np.testing.assert_allclose(ranges["chain"], np.degrees(comp.joint_ranges), rtol=0, atol=1e-12)


@pytest.mark.parametrize("merge_on", ["targets", "chain"])
def test_merge_below_applies_to_the_ranges_merge_on_names(merge_on: str) -> None:
    base = synthesize(arcs_problem(merge_below=math.radians(179.0)))
    comp = base.compound
    assert comp is not None and comp.target_ranges is not None
    ranges = comp.target_ranges if merge_on == "targets" else comp.joint_ranges
    for threshold in (float(ranges.min()) * 0.999, float(ranges.max()) * 1.001):
        result = synthesize(arcs_problem(merge_below=threshold, merge_on=merge_on))
        assert result.compound is not None and result.compound.merge_on == merge_on
        expected = tuple(i for i, v in enumerate(ranges) if v < threshold)
        assert result.compound.merged == expected


def wavy(length: float, amplitude: float, n: int = 200) -> np.ndarray:
    x = np.linspace(0.0, length, n)
    return np.column_stack([x, amplitude * np.sin(2 * np.pi * x / 6.0) + 0.05 * x**2])


def wavy_problem(**kw: object) -> Problem:
    profiles = (wavy(8.0, 0.6), wavy(9.5, 0.7), wavy(11.0, 0.8))
    settings: dict[str, object] = {"piece_length": 0.3, "min_pieces": 3, "design": "MCMC", "starts": 1}
    settings.update(kw)
    return Problem(profiles=profiles, **settings)  # type: ignore[arg-type]


def test_the_search_starts_from_the_given_segment_matrix() -> None:
    targets = target_profiles(wavy_problem())
    pieces = [t.pieces for t in targets]
    sm = np.array([[3, 3, 3], [5, 8, 12], [4, 4, 4], [0, 0, 0]])
    sm[3] = np.asarray(pieces) - sm[:3].sum(axis=0)
    result = synthesize(wavy_problem(initial_segment_matrix=sm))
    first = SegmentFitter(targets).error_matrix("MCMC", sm)
    assert result.history[0][0] == first.max()  # E_max of the given SM is the first of the history
    assert len(result.history) == 1 and len(result.history[0]) > 1
    assert result.e_max <= first.max()
    even = synthesize(wavy_problem())
    assert even.history[0][0] != first.max()
    with pytest.raises(SpecError, match="initial_segment_matrix: is not a valid segment matrix"):
        synthesize(wavy_problem(initial_segment_matrix=sm + 1))
    with pytest.raises(SpecError, match="initial_segment_matrix: needs a design vector"):
        synthesize(wavy_problem(design=None, segments=4, initial_segment_matrix=sm))


TOML = """
profiles = ["a.csv", "b.csv", "c.csv"]
piece_length = 0.3
min_pieces = 3
design = "MCMC"
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name, (length, amplitude) in zip("abc", ((8.0, 0.6), (9.5, 0.7), (11.0, 0.8)), strict=True):
        save_profile(tmp_path / f"{name}.csv", wavy(length, amplitude))
    return tmp_path


def write(folder: Path, extra: str) -> Path:
    path = folder / "problem.toml"
    path.write_text(TOML + extra, encoding="utf-8")
    return path


def test_problem_file_keys(folder: Path) -> None:
    rows = "initial_segment_matrix = [[3, 5, 4, 14], [3, 8, 4, 16], [3, 12, 4, 17]]\n"
    problem = load_problem(
        write(folder, rows + 'merge_on = "chain"\nrank_by = "joints"\ne_max_tolerance = 0.1\n')
    )
    np.testing.assert_array_equal(
        problem.initial_segment_matrix, [[3, 3, 3], [5, 8, 12], [4, 4, 4], [14, 16, 17]]
    )
    assert (problem.merge_on, problem.rank_by, problem.e_max_tolerance) == ("chain", "joints", 0.1)
    default = load_problem(write(folder, ""))
    assert (default.merge_on, default.rank_by, default.e_max_tolerance) == ("targets", "error", None)
    assert default.initial_segment_matrix is None


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ('merge_on = "both"\n', 'merge_on: expected one of "targets", "chain", got "both"'),
        ('rank_by = "joints"\n', 'e_max_tolerance: missing; rank_by = "joints" needs'),
        ("e_max_tolerance = -1\n", "e_max_tolerance: expected a positive number"),
        ("initial_segment_matrix = [[3, 5, 4, 14]]\n", "initial_segment_matrix: has 1 rows"),
        ("initial_segment_matrix = [[3, 5], [3, 8], [3, 12]]\n", 'has 2 entries per row but design "MCMC"'),
        (
            'initial_segment_matrix = [["a"]]\n',
            "initial_segment_matrix: expected a list of rows of whole numbers",
        ),
    ],
)
def test_problem_file_key_errors(folder: Path, extra: str, message: str) -> None:
    with pytest.raises(SpecError, match=message.replace("(", r"\(")):
        load_problem(write(folder, extra))
