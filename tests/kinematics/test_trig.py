"""The branch-free sine, cosine and arctangent against numpy's (the C library's) over many arguments, edge cases
included, and their loops compiled to packed instructions."""

from __future__ import annotations

import re

import numba
import numpy as np
import pytest

from linkwork.kinematics import trig

ULPS = 1.0  # fdlibm's polynomials: within one unit in the last place of numpy's value


def ulps(value: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``|value - reference|`` in units of the last place of ``reference`` (at least the smallest subnormal)."""
    return np.abs(value - reference) / np.spacing(np.maximum(np.abs(reference), np.finfo(float).tiny))


@pytest.fixture(scope="module")
def rng() -> np.random.Generator:
    return np.random.default_rng(20261125)


def test_sincos_within_an_ulp_of_numpy(rng: np.random.Generator) -> None:
    """Arguments of every size up to the fast path's limit and beyond (the C library's fall-back), multiples of
    ``pi/4`` (the quadrant boundaries), signed zeros, subnormals, infinities and NaN."""
    x = np.concatenate(
        [
            rng.uniform(-10.0, 10.0, 200_000),
            rng.uniform(-trig.SINCOS_LIMIT, trig.SINCOS_LIMIT, 50_000),
            np.arange(-64, 65) * (np.pi / 4.0),
            np.nextafter(np.arange(-8, 9) * (np.pi / 4.0), np.inf),
            [0.0, -0.0, 5e-324, -1e-300, 1e-8, trig.SINCOS_LIMIT, 2e6, -1e12, 1e300, np.inf, -np.inf, np.nan],
        ]
    )
    c, s = np.empty_like(x), np.empty_like(x)
    trig.sincos_into(x, c, s)
    finite = np.isfinite(x)
    with np.errstate(invalid="ignore"):
        ref_c, ref_s = np.cos(x), np.sin(x)
    assert np.max(ulps(c[finite], ref_c[finite])) <= ULPS
    assert np.max(ulps(s[finite], ref_s[finite])) <= ULPS
    assert np.all(np.isnan(c[~finite])) and np.all(np.isnan(s[~finite]))
    zeros, c0, s0 = np.array([0.0, -0.0]), np.empty(2), np.empty(2)
    trig.sincos_into(zeros, c0, s0)
    assert c0.tolist() == [1.0, 1.0] and np.signbit(s0).tolist() == [False, True]


def test_atan2_within_an_ulp_of_numpy(rng: np.random.Generator) -> None:
    """Points of every quadrant and scale, on the axes and the diagonals, signed zeros and infinities."""
    n = 200_000
    y = rng.normal(size=n) * 10.0 ** rng.integers(-8, 8, n)
    x = rng.normal(size=n) * 10.0 ** rng.integers(-8, 8, n)
    angles = np.linspace(-np.pi, np.pi, 4097)
    special = [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0), (1.0, 0.0), (-1.0, -0.0), (0.0, -2.0)]
    special += [(-0.0, -2.0), (1.0, 1.0), (-1.0, -1.0), (1e-300, 1.0), (3.0, np.inf), (np.inf, -np.inf)]
    special += [(5e-324, -1.0), (1.0, 1e-300), (np.nan, 1.0)]
    y = np.concatenate([y, np.sin(angles), 0.4375 * np.ones(1), 0.6875 * np.ones(1), [p[0] for p in special]])
    x = np.concatenate([x, np.cos(angles), np.ones(2), [p[1] for p in special]])
    out = np.empty_like(y)
    trig.atan2_into(y, x, out)
    ref = np.arctan2(y, x)
    number = ~np.isnan(ref)
    assert np.max(ulps(out[number], ref[number])) <= ULPS
    assert np.array_equal(np.signbit(out[number]), np.signbit(ref[number]))  # signed zeros and +-pi
    assert np.all(np.isnan(out[~number]))


def test_atan2_of_a_near_identity_rotation_is_the_quotient(rng: np.random.Generator) -> None:
    """Where ``c > 0`` and ``|s| < 1e-9 c`` (a closed loop's product, turned by round-off), ``atan2(s, c)`` is
    ``s / c`` to the last bit: ``atan z = z (1 - z^2/3 + ...)`` rounds to ``z`` below ``sqrt(3) 2^-27``. The planar
    closure's loop log (:func:`linkwork.kinematics.dyad_solver.loop_log`) divides instead there; both the
    branch-free arctangent and numpy's must agree exactly."""
    c = np.concatenate(
        [rng.uniform(0.5, 2.0, 100_000), 1.0 - rng.uniform(0.0, 1e-12, 10_000), [1.0, 1e-3, 1e3]]
    )
    z = rng.uniform(-1.0, 1.0, c.size) * 10.0 ** rng.uniform(-300.0, -9.0, c.size)
    s = np.concatenate([z[:-3] * c[:-3], [0.0, -0.0, 5e-324]])
    assert np.all(np.abs(s) < 1e-9 * c)
    out = np.empty_like(s)
    trig.atan2_into(s, c, out)
    quotient = s / c
    assert np.array_equal(out, quotient) and np.array_equal(np.signbit(out), np.signbit(quotient))
    assert np.array_equal(np.arctan2(s, c), quotient)


@pytest.mark.parametrize("name", ["sincos_into", "atan2_into"])
def test_loops_use_packed_instructions(name: str) -> None:
    """The point of these kernels: their loops compile to packed (ymm / zmm) arithmetic, no C library call in the
    fast loop (the fall-back loop's calls aside)."""
    fresh = numba.njit(error_model="numpy")(getattr(trig, name).py_func)  # cached code cannot be inspected
    x = np.linspace(-3.0, 3.0, 16)
    fresh(x, x.copy(), x.copy())
    asm = "\n".join(fresh.inspect_asm().values())
    assert re.search(r"\bv(mul|add|div|sub)pd\b[^\n]*%[yz]mm", asm), "no packed double arithmetic"
