"""End-to-end synthesis: exact cases, invariances, the joining constraints and the chain.json contract."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.synthesis import Problem, synthesize, write_target_profiles_csv
from linkwork.synthesis.frames import rotation


def wavy(length: float, amplitude: float, n: int = 200) -> np.ndarray:
    x = np.linspace(0.0, length, n)
    return np.column_stack([x, amplitude * np.sin(2 * np.pi * x / 6.0) + 0.05 * x**2])


def wavy_problem(**kw: object) -> Problem:
    profiles = (wavy(8.0, 0.6), wavy(9.5, 0.7), wavy(11.0, 0.8))
    settings: dict[str, object] = {
        "piece_length": 0.3,
        "min_pieces": 3,
        "design": "MCMC",
        "starts": 3,
        "seed": 7,
    }
    settings.update(kw)
    return Problem(profiles=profiles, **settings)  # type: ignore[arg-type]


def check_joined_errors(result) -> None:  # type: ignore[no-untyped-def]
    """The reported joined errors recomputed from the reported points (tolerance 1e-12)."""
    starts = np.vstack(
        [np.zeros((1, result.segment_matrix.shape[1]), int), np.cumsum(result.segment_matrix, 0)]
    )
    for j, (prof, target) in enumerate(zip(result.joined, result.targets, strict=True)):
        assert prof.points.shape == target.points.shape
        dist = np.linalg.norm(prof.points - target.points, axis=1)
        for e in range(len(result.design)):
            assert result.joined_error_matrix[e, j] == pytest.approx(
                dist[starts[e, j] : starts[e + 1, j] + 1].max(), abs=1e-12
            )
        np.testing.assert_allclose(prof.joints, prof.points[starts[:, j]], rtol=0, atol=1e-12)
    assert result.joined_e_max == pytest.approx(result.joined_error_matrix.max(), abs=0)


def test_straight_lines_of_different_length_are_matched_exactly() -> None:
    lines = tuple(
        np.array([[0.0, 0.0], [length, 0.0]]) @ rotation(a).T for length, a in ((3.0, 0.0), (4.2, 1.0))
    )
    result = synthesize(Problem(profiles=lines, piece_length=0.3, min_pieces=2, design="MC"))
    assert result.e_max < 1e-12
    assert result.joined_e_max < 1e-9
    check_joined_errors(result)


def test_open_profiles_errors_and_contract() -> None:
    result = synthesize(wavy_problem())
    check_joined_errors(result)
    sm = result.segment_matrix
    np.testing.assert_array_equal(sm.sum(axis=0), [t.pieces for t in result.targets])
    assert np.all(sm[0] == sm[0, 0]) and np.all(sm[2] == sm[2, 0])
    assert result.e_max == pytest.approx(result.error_matrix.max(), abs=0)
    assert result.e_mean == pytest.approx(result.error_matrix.mean(), abs=1e-15)  # Eq. (24)
    data = json.loads(json.dumps(result.to_dict()))
    for key in (
        "profiles",
        "design",
        "segment_matrix",
        "error_matrix",
        "e_max",
        "e_mean",
        "segments",
        "compound",
    ):
        assert key in data
    assert set(data["profiles"][0]) >= {"arc_length", "pieces", "target_length"}
    assert set(data["joined"]) >= {"error_matrix", "e_max", "profiles"}
    assert set(data["joined"]["profiles"][0]) >= {"joints", "points"}
    assert [s["type"] for s in data["segments"]] == list("MCMC")
    assert "shape" in data["segments"][0] and "radius" in data["segments"][1]
    assert data["joined"]["profiles"][0]["angles"][1] == pytest.approx(
        math.degrees(result.joined[0].angles[1]), abs=1e-12
    )


def test_rigid_motion_of_the_profile_set_leaves_every_error_unchanged() -> None:
    base = wavy_problem()
    rot, shift = rotation(2.1), np.array([40.0, -13.0])
    moved = Problem(**{**base.__dict__, "profiles": tuple(p @ rot.T + shift for p in base.profiles)})
    a, b = synthesize(base), synthesize(moved)
    np.testing.assert_array_equal(a.segment_matrix, b.segment_matrix)
    np.testing.assert_allclose(a.error_matrix, b.error_matrix, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.joined_error_matrix, b.joined_error_matrix, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.joined[1].points, a.joined[1].points @ rot.T + shift, rtol=0, atol=1e-9)


def test_closed_profiles_close_the_chain() -> None:
    t = np.linspace(0.0, 2 * np.pi, 300)
    profiles = tuple(np.column_stack([a * np.cos(t), b * np.sin(t)]) for a, b in ((2.0, 1.5), (2.4, 1.6)))
    result = synthesize(
        Problem(profiles=profiles, kind="closed", piece_length=0.25, min_pieces=3, design="CMCM", starts=2)
    )
    check_joined_errors(result)
    for prof in result.joined:
        assert np.linalg.norm(prof.joints[-1] - prof.joints[0]) < 1e-9
        assert np.linalg.norm(prof.points[-1] - prof.points[0]) < 1e-9


def test_fixed_end_profiles_pin_both_ends() -> None:
    x = np.linspace(0.0, 4.0, 150)
    profiles = tuple(np.column_stack([x, h * np.sin(np.pi * x / 4.0)]) for h in (0.5, 1.0, 1.5))
    result = synthesize(
        Problem(profiles=profiles, kind="fixed-end", piece_length=0.1, min_pieces=4, design="CMC", starts=2)
    )
    check_joined_errors(result)
    for prof in result.joined:
        assert np.linalg.norm(prof.joints[0] - [0.0, 0.0]) < 1e-9
        assert np.linalg.norm(prof.joints[-1] - [4.0, 0.0]) < 1e-9


def test_auto_design_ranking_progress_and_compound() -> None:
    calls: list[tuple[int, int]] = []
    problem = wavy_problem(design=None, segments=3, starts=2, merge_below=math.radians(60.0))
    result = synthesize(problem, progress=lambda done, total: calls.append((done, total)))
    assert len(result.stats.designs) == 2**3 - 1
    ranked = [d.joined_e_max for d in result.stats.designs if d.joined_e_max is not None]
    assert ranked == sorted(ranked) and result.joined_e_max == ranked[0]
    for d in result.stats.designs:  # a design left unjoined has a bound above the best joined E_max
        assert d.joined_e_max is not None or d.bound > result.joined_e_max
    assert calls[-1][0] == calls[-1][1] == 7 * 3 and [c[0] for c in calls] == list(range(1, 22))
    comp = result.compound
    assert comp is not None
    np.testing.assert_allclose(comp.joint_ranges, np.ptp(comp.joint_angles, axis=1), rtol=0, atol=1e-15)
    for i in comp.merged:  # a merged joint has the same angle on every profile: its mean (tolerance 1e-9)
        assert result.design[i] == "C" or result.design[i + 1] == "C"
        sm = result.segment_matrix
        for j, prof in enumerate(comp.profiles):
            k = int(sm[: i + 1, j].sum())
            p_in, p_out = prof.points[k] - prof.points[k - 1], prof.points[k + 1] - prof.points[k]
            angle = math.atan2(p_in[0] * p_out[1] - p_in[1] * p_out[0], float(p_in @ p_out))
            assert angle == pytest.approx(comp.joint_angles[i].mean(), abs=1e-9)
    json.dumps(result.to_dict())


def test_seeded_search_is_reproducible() -> None:
    a, b = synthesize(wavy_problem()), synthesize(wavy_problem())
    np.testing.assert_array_equal(a.segment_matrix, b.segment_matrix)
    assert a.history == b.history


def test_refined_search_is_never_worse() -> None:
    paper = synthesize(wavy_problem())
    refined = synthesize(wavy_problem(), search="refined")
    assert refined.stats.paper_e_max == pytest.approx(paper.e_max, abs=0)
    assert refined.e_max <= paper.e_max + 1e-15
    assert refined.joined_e_max <= paper.joined_e_max + 1e-15


def test_target_profiles_csv(tmp_path: Path) -> None:
    result = synthesize(wavy_problem(starts=1))
    out = tmp_path / "target_profiles.csv"
    write_target_profiles_csv(result.targets, out)
    with open(out, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == sum(t.pieces + 1 for t in result.targets)
    assert float(rows[1]["x"]) == result.targets[0].points[1, 0]  # repr round-trips exactly
