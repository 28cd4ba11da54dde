"""The hinge-error model against its definition, and the percentile bands against numpy's percentiles.

* uniform errors stay inside the tolerances (tilt cone, shift disc) and fill them (largest near the bound);
  normal errors have the tolerance as standard deviation per component;
* a perturbed hinge line makes exactly the drawn angle with the nominal one, and is moved normal to it by the
  drawn shift (distance between the lines at the nominal point);
* seeds depend on the study seed and the sample index only;
* band percentiles from the log-histograms are within their resolution (2.3 %) of numpy's.
"""

from __future__ import annotations

import numpy as np

import linkwork as lw
from linkwork.studies import bands
from linkwork.studies.imperfections import (
    HingeLines,
    ImperfectionModel,
    hinge_errors,
    perturbed_twists,
    sample_seeds,
)
from linkwork.studies.scale import misfit_scale


def _setup(distribution: str):
    mech = lw.load("bennett")
    lines = HingeLines.of(mech, misfit_scale(mech).centre)
    model = ImperfectionModel(2e-3, np.radians(0.1), distribution=distribution)
    errors = hinge_errors(sample_seeds(7, 0, 20000), mech, model, lines)
    return mech, lines, model, errors


def test_uniform_errors_fill_the_tolerances():
    _, _, model, errors = _setup("uniform")
    tilt = np.linalg.norm(errors[..., :2], axis=-1)
    shift = np.linalg.norm(errors[..., 2:], axis=-1)
    assert tilt.max() <= model.direction_tol and shift.max() <= model.position_tol
    assert tilt.max() > 0.99 * model.direction_tol and shift.max() > 0.99 * model.position_tol
    # uniform in a disc: the radius has P(r < R/2) = 1/4 (80,000 draws: 4 standard errors is 0.006)
    assert abs(np.mean(shift < model.position_tol / 2) - 0.25) < 0.006


def test_normal_errors_have_the_tolerance_as_standard_deviation():
    _, _, model, errors = _setup("normal")
    # 40,000 draws per component kind: the sample standard deviation is within 1.5 % (4 standard errors)
    assert abs(errors[..., :2].std() / model.direction_tol - 1.0) < 0.015
    assert abs(errors[..., 2:].std() / model.position_tol - 1.0) < 0.015
    assert abs(errors.mean(axis=(0, 1))).max() < 4 * model.position_tol / np.sqrt(80000)


def test_perturbed_lines_have_the_drawn_tilt_and_shift():
    _, lines, _, errors = _setup("normal")
    errors = errors[:50]
    twists = perturbed_twists(errors, lines)
    w = twists[..., :3]
    angle = np.arccos(np.clip(np.einsum("sni,ni->sn", w, lines.directions), -1.0, 1.0))
    np.testing.assert_allclose(angle, np.linalg.norm(errors[..., :2], axis=-1), rtol=1e-6, atol=1e-12)
    # the new line passes through the nominal point moved by the shift (normal to the nominal line)
    moved = lines.points + errors[..., 2:3] * lines.e1 + errors[..., 3:4] * lines.e2
    v = twists[..., 3:]
    np.testing.assert_allclose(np.cross(moved, w), v, atol=1e-14)  # v = p x w for every p on the line
    np.testing.assert_allclose(np.einsum("ni,ni->n", lines.e1, lines.directions), 0.0, atol=1e-14)


def test_seeds_depend_on_study_seed_and_index_only():
    a = sample_seeds(3, 0, 100)
    np.testing.assert_array_equal(sample_seeds(3, 40, 60), a[40:60])
    assert len(set(a.tolist())) == 100
    assert not np.array_equal(sample_seeds(4, 0, 100), a)


def test_band_percentiles_within_their_resolution():
    rng = np.random.default_rng(0)
    values = np.exp(rng.normal(-7.0, 1.5, size=(5000, 3)))
    values[:100, 0] = 0.0
    counts = bands.histogram(values, 1.0)
    assert counts.sum() == values.size
    for q in (0.05, 0.5, 0.95):
        got = bands.percentiles(counts, q, 1.0)
        want = np.quantile(values, q, axis=0, method="inverted_cdf")
        np.testing.assert_allclose(got, want, rtol=0.024)  # one bin: 10^(1/100) - 1 = 2.3 %
