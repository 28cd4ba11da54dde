"""The example sets: the NACA formulas against their published values, the committed files against the script
that writes them, and every example through the synthesis engine."""

from __future__ import annotations

import importlib.util
import math
import time
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from linkwork.data import EXAMPLES, example
from linkwork.io.problem import load_problem
from linkwork.io.profiles import load_profile
from linkwork.synthesis import synthesize, target_profiles

ROOT = Path(__file__).resolve().parents[2]


def load_script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("make_examples", ROOT / "examples" / "make_examples.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


make_examples = load_script()


def arc_length(points: np.ndarray) -> float:
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T)))


# ------------------------------------------------------------------------------------------------ NACA


def test_naca0012_thickness_at_thirty_percent_chord() -> None:
    # y_t = 5 t (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 - 0.1015 x^4), Abbott & von Doenhoff
    # Eq. 6.2, evaluated by hand at x = 0.3 for t = 0.12: 0.6 * 0.100035... = 0.0600210...
    by_hand = 0.6 * (
        0.2969 * math.sqrt(0.3) - 0.1260 * 0.3 - 0.3516 * 0.09 + 0.2843 * 0.027 - 0.1015 * 0.0081
    )
    assert make_examples.naca4_thickness(np.array(0.3), 0.12) == pytest.approx(by_hand, abs=1e-15)
    assert by_hand == pytest.approx(0.0600, abs=1e-4)  # the tabulated NACA 0012 ordinate at 30 % chord


def test_naca0012_maximum_thickness_is_twelve_percent_near_thirty_percent_chord() -> None:
    x = np.linspace(0.0, 1.0, 100_001)
    thickness = 2.0 * make_examples.naca4_thickness(x, 0.12)
    assert thickness.max() == pytest.approx(0.12, abs=1e-3)
    assert x[np.argmax(thickness)] == pytest.approx(0.30, abs=1e-2)
    # Open trailing edge: 2 y_t(1) = 10 t (sum of the coefficients) = 1.2 * 0.0021.
    assert thickness[-1] == pytest.approx(1.2 * 0.0021, abs=1e-12)


def test_naca_camber_line_peaks_at_p_with_value_m() -> None:
    x = np.linspace(0.0, 1.0, 100_001)
    camber, slope = make_examples.naca4_camber(x, 0.04, 0.4)
    assert camber.max() == pytest.approx(0.04, abs=1e-12)
    assert x[np.argmax(camber)] == pytest.approx(0.4, abs=1e-5)
    assert camber[0] == pytest.approx(0.0, abs=1e-15) and camber[-1] == pytest.approx(0.0, abs=1e-15)
    # The slope is the derivative of the camber line (central differences, step 1e-5: error ~1e-9).
    np.testing.assert_allclose(np.gradient(camber, x)[1:-1], slope[1:-1], rtol=0, atol=1e-6)


def test_naca_outline_is_selig_ordered_and_scaled() -> None:
    outline = make_examples.naca4_outline("2412", chord=1.5, points=61)
    assert outline.shape == (121, 2)
    np.testing.assert_allclose(outline[60], [0.0, 0.0], rtol=0, atol=1e-15)  # nose at the origin
    assert outline[0, 0] == pytest.approx(1.5, abs=1e-3) and outline[0, 1] > outline[-1, 1]  # upper TE first
    # Upper and lower points are the camber line offset by +-y_t along its normal (Abbott & von Doenhoff
    # Eq. 6.1): their midpoint is on the camber line and their half distance is y_t.
    upper, lower = outline[60::-1] / 1.5, outline[60:] / 1.5
    x = 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, 61)))
    camber, _ = make_examples.naca4_camber(x, 0.02, 0.4)
    np.testing.assert_allclose((upper + lower) / 2.0, np.column_stack([x, camber]), rtol=0, atol=1e-12)
    half = np.hypot(*(upper - lower).T) / 2.0
    np.testing.assert_allclose(half, make_examples.naca4_thickness(x, 0.12), rtol=0, atol=1e-12)


# -------------------------------------------------------------------------------------------- the sets


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_problem_loads(name: str) -> None:
    problem = load_problem(example(name))
    expected = 6 if name == "wing-six" else 3  # the paper's three profiles; wing-six has six
    assert problem.count == expected
    assert len(set(problem.names)) == expected


def test_wing_arc_lengths_differ_by_at_least_thirty_percent() -> None:
    problem = load_problem(example("wing"))
    lengths = [arc_length(p) for p in problem.profiles]
    assert lengths == sorted(lengths)
    assert lengths[-1] / lengths[0] >= 1.3


def test_fixed_end_arches_share_their_ends() -> None:
    problem = load_problem(example("fixed-end"))
    assert {Path(p).suffix for p in ("low_arch.svg", "high_arch.dxf")} == {".svg", ".dxf"}
    for profile in problem.profiles:
        np.testing.assert_allclose(profile[[0, -1]], [[0.0, 0.0], [4.0, 0.0]], rtol=0, atol=1e-9)


def test_seat_has_the_papers_arc_lengths_and_piece_counts() -> None:
    problem = load_problem(example("seat"))
    lengths = [arc_length(p) for p in problem.profiles]
    np.testing.assert_allclose(lengths, [44.42, 51.98, 54.39], rtol=0, atol=1e-9)
    pieces = [t.pieces for t in target_profiles(problem)]
    # The paper's Sec. 8.2 lists 127, 149, 155 at s_d = 0.35; the procedure may land one piece off.
    np.testing.assert_allclose(pieces, [127, 149, 155], rtol=0, atol=1)


def test_the_one_bundled_copy_is_what_the_script_writes(tmp_path: Path) -> None:
    make_examples.main(tmp_path)
    for name in EXAMPLES:
        bundled_dir = example(name).parent
        bundled = sorted(p.name for p in bundled_dir.iterdir())
        fresh = sorted(p.name for p in (tmp_path / "src" / "linkwork" / "data" / "examples" / name).iterdir())
        assert bundled == fresh
        for file in bundled:
            ours = bundled_dir / file
            again = tmp_path / "src" / "linkwork" / "data" / "examples" / name / file
            if ours.suffix == ".dxf":  # DXF headers carry creation times and GUIDs: compare the curves
                np.testing.assert_allclose(load_profile(again), load_profile(ours), rtol=0, atol=1e-12)
            else:
                assert ours.read_bytes() == again.read_bytes(), f"{name}/{file}"


def test_examples_folder_holds_no_second_copy() -> None:
    for name in EXAMPLES:
        assert not (ROOT / "examples" / name).exists(), f"examples/{name} duplicates the bundled data"


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "e_max_bound"),
    # Upper bounds on the joined chain's E_max, about 1.5x what the engine reaches (a regression guard), in
    # the profiles' units: chord 1 wing, unit circle, arches 4 long, seat in inches.
    [("wing", 0.015), ("closed", 0.11), ("fixed-end", 0.05), ("seat", 0.26)],
)
def test_example_synthesises_in_seconds(name: str, e_max_bound: float) -> None:
    problem = load_problem(example(name))
    start = time.perf_counter()
    result = synthesize(problem)
    seconds = time.perf_counter() - start
    assert seconds < 60.0
    assert result.joined_e_max <= e_max_bound
