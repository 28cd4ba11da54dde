"""Writes ``src/linkwork/kinematics/bidiagonal_7x6.py``: the Householder bidiagonalisation of ``7 x 6`` matrices
(``J^T`` of a two-loop planar Jacobian) and the tangent ``U e_7``, unrolled into straight-line code over one loop of
points, each point's 42 entries in local variables, two points (``p`` and ``p + HALF``) per iteration with their
statements interleaved.

The statements are those of the lane loops they replace (``bidiagonal_rows.chunk_reflect`` / ``chunk_apply`` /
``chunk_bidiagonal`` / ``chunk_tangent`` before), written out with every index a literal: the same reflections, the
same inner products summed in the same order. A test (``tests/kinematics/test_bidiagonal_7x6.py``) checks that the
checked-in module is this script's output.

Run: ``python tools/generate_bidiagonal_7x6.py`` (``--check``: exit 1 if the module differs).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

TARGET = Path(__file__).resolve().parents[1] / "src" / "linkwork" / "kinematics" / "bidiagonal_7x6.py"
ROWS, COLS = 7, 6  # J^T: m x E

HEADER = '''"""The Householder bidiagonalisation of ``7 x 6`` matrices (``J^T`` of two-loop planar Jacobians) and the tangent
``t = U e_7``, :data:`CHUNK` points at a time, unrolled: **generated** by ``tools/generate_bidiagonal_7x6.py`` (do
not edit by hand; a test checks that this file is its output).

:func:`reduce_points` is one loop over the points whose body is the whole reduction written out, each point's 42
entries in local variables: LLVM keeps them in registers (or the stack, never a streamed array) and vectorises the
loop across points (the rows of ``B`` are :data:`CHUNK` apart, a constant, so that the stores provably do not meet
the loads of later points). One point's reduction is a chain of dependent operations (each reflection's sum of
squares, square root and division waits for the one before), so its latency, not its arithmetic, bounds the time:
each iteration reduces two points, ``p`` and ``p + HALF``, their statements interleaved, two independent chains
that the processor overlaps (on the Watt six-bar's Jacobians, 83-90 ns a point with one chain, 63-68 with two;
four chains spill too much and take 300). Each point's arithmetic is unchanged. The arithmetic is that of Golub & Van Loan Alg. 5.4.2 as
:mod:`linkwork.kinematics.bidiagonal_rows` explains it: for each column ``k`` a reflection from the left zeroes
``M[k+1:, k]`` (``alpha = -sign(x) |v|``, ``v = x - alpha e_1``, ``beta = 1 / (|x| (|x| + |x_1|))``, the identity
for a zero vector), applied to the columns right of ``k`` as ``y -= beta (v . y) v``; then one from the right
zeroes ``M[k, k+2:]``, applied to the rows below ``k``; the tangent is ``e_7`` with the left reflections applied
last to first, normalised. Every inner product is summed in the same order as in the lane loops it replaces
(pivot first, then down the column or along the row), each product rounded at most once (a fused multiply-add
where LLVM contracts one, which only removes a rounding): the constants of Higham's Lemma 19.2, and so
:func:`linkwork.kinematics.bidiagonal_rows.reduction_bound`, hold unchanged.

References
----------
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., Johns Hopkins (2013), Alg. 5.4.2.
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002), Lemma 19.2.
"""

from __future__ import annotations

import math

from linkwork.kernel_cache import kernel

CHUNK = 256
"""Points reduced together, the length of each row of ``B`` (a multiple of the lanes of the roots, 16; about
60 kB of rows for ``7 x 6``)."""
HALF = CHUNK // 2
"""Each iteration reduces points ``p`` and ``p + HALF``."""
FLOOR = 1e-300
"""A reflection whose ``|v|^2 / 2`` is below this is the identity (its factor is 0)."""
D = 42
"""``B``'s rows from here: the diagonal ``d`` of ``B`` (6 rows), then the superdiagonal ``e`` (5), ``det(U)
det(V)`` (1) and the unit tangent (7); rows ``0 .. 41`` are ``J^T`` (row ``a * 6 + e`` is ``J[e, a]``)."""
F = D + 6
"""The superdiagonal's first row."""
DET = F + 5
"""The row of ``det(U) det(V)``."""
T = DET + 1
"""The tangent's first row."""
ROWS = T + 7
"""``B``'s rows."""


@kernel(error_model="numpy", fastmath={"contract"})
def reduce_points(B, n):
    """Reduces the ``n`` (``<= CHUNK``) matrices ``J^T`` (``7 x 6``) of ``B`` (flat, ``ROWS x CHUNK``: row ``r``
    of point ``p`` at ``B[r * CHUNK + p]``) to upper bidiagonal form by Householder reflections from the left and
    the right (Golub & Van Loan Alg. 5.4.2), writing the diagonal, the superdiagonal, ``det(U) det(V)`` (``-1``
    for each reflection made) and the unit tangent ``U e_7`` into rows ``D ..``; rows ``0 .. 41`` are read only.
    Points ``n .. 2 HALF - 1`` (``n .. n + HALF - 1`` when ``n < HALF``) are reduced too, from whatever finite or
    NaN values their rows hold, and their results ignored: no division or square root can raise."""
    for p in range(min(n, HALF)):
'''


class Writer:
    """Collects the loop body's statements (indented once inside ``for p in range(n):``)."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def __call__(self, text: str) -> None:
        self.lines.append("        " + text)


def summed(w: Writer, name: str, terms: list[str]) -> None:
    """``name = sum(terms)``, one term after the other (the order of the lane loops this code replaces)."""
    w(f"{name} = {terms[0]}")
    for term in terms[1:]:
        w(f"{name} += {term}")


def reflect(w: Writer, pivot: str, rest: list[str], head: str, factor: str) -> None:
    """A reflection that zeroes ``rest`` below (or right of) ``pivot``: its first entry into ``head``, its factor
    into ``factor``, the pivot becomes ``alpha``; ``sign`` changes unless it is the identity."""
    summed(w, "acc", [f"{y} * {y}" for y in [pivot, *rest]])
    w("norm = math.sqrt(acc)")
    w(f"alpha = -norm if {pivot} >= 0.0 else norm")
    w(f"vv = norm * (norm + abs({pivot}))  # |x - alpha e_1|^2 / 2")
    w(f"{factor} = 1.0 / vv if vv > FLOOR else 0.0")
    w(f"{head} = {pivot} - alpha")
    w(f"{pivot} = alpha")
    w(f"sign = -sign if {factor} > 0.0 else sign")


def apply(w: Writer, head: str, factor: str, vector: list[str], top: str, target: list[str]) -> None:
    """``y -= beta (v . y) v`` for ``y = [top; target]``, ``v = [head; vector]``."""
    summed(w, "dot", [f"{head} * {top}"] + [f"{u} * {v}" for u, v in zip(vector, target, strict=True)])
    w(f"dot *= {factor}")
    w(f"{top} -= dot * {head}")
    for u, v in zip(vector, target, strict=True):
        w(f"{v} -= dot * {u}")


def body() -> list[str]:
    """The loop body: loads, the reduction, the tangent, stores."""
    m, E = ROWS, COLS
    w = Writer()

    def entry(a: int, e: int) -> str:
        return f"m{a}{e}"

    for a in range(m):
        for e in range(E):
            w(f"{entry(a, e)} = B[{a * E + e} * CHUNK + p]")
    w("sign = 1.0")
    for k in range(E):
        below = [entry(a, k) for a in range(k + 1, m)]
        w(f"# From the left: column {k}, rows {k} .. {m - 1}.")
        reflect(w, entry(k, k), below, f"hl{k}", f"bl{k}")
        for c in range(k + 1, E):
            apply(w, f"hl{k}", f"bl{k}", below, entry(k, c), [entry(a, c) for a in range(k + 1, m)])
        if k >= E - 2:
            continue
        right = [entry(k, c) for c in range(k + 2, E)]
        w(f"# From the right: row {k}, columns {k + 1} .. {E - 1}.")
        reflect(w, entry(k, k + 1), right, f"hr{k}", f"br{k}")
        for a in range(k + 1, m):
            apply(w, f"hr{k}", f"br{k}", right, entry(a, k + 1), [entry(a, c) for c in range(k + 2, E)])
    w(f"# The tangent U e_{m}: the left reflections applied last to first.")
    for a in range(m):
        w(f"t{a} = {1.0 if a == m - 1 else 0.0}")
    for k in range(E - 1, -1, -1):
        below = [entry(a, k) for a in range(k + 1, m)]
        apply(w, f"hl{k}", f"bl{k}", below, f"t{k}", [f"t{a}" for a in range(k + 1, m)])
    w("acc = 0.0")
    for a in range(m):
        w(f"acc += t{a} * t{a}")
    w("acc = 1.0 / math.sqrt(acc)  # 1 to a few rounding errors")
    for k in range(E):
        w(f"B[(D + {k}) * CHUNK + p] = {entry(k, k)}")
    for k in range(E - 1):
        w(f"B[(F + {k}) * CHUNK + p] = {entry(k, k + 1)}")
    w("B[DET * CHUNK + p] = sign")
    for a in range(m):
        w(f"B[(T + {a}) * CHUNK + p] = t{a} * acc")
    return w.lines


LOCALS = re.compile(r"\b(m\d\d|hl\d|bl\d|hr\d|br\d|t\d|acc|norm|alpha|vv|sign|dot)\b")
"""The loop body's local variables (renamed for each of the two points of an iteration)."""


def point(line: str, suffix: str, offset: str) -> str:
    """``line`` of the body for one of an iteration's points: its locals suffixed, its index ``p`` moved by
    ``offset`` (a trailing comment kept on the first point's line only)."""
    code, mark, comment = line.partition("  # ")
    code = LOCALS.sub(lambda found: found.group(1) + suffix, code).replace(" + p]", f" + p{offset}]")
    return code + mark + comment if suffix == "_a" else code


def interleaved(lines: list[str]) -> list[str]:
    """The body for points ``p`` (suffix ``_a``) and ``p + HALF`` (``_b``), statement after statement."""
    out = []
    for line in lines:
        out.append(point(line, "_a", ""))
        if not line.strip().startswith("#"):
            out.append(point(line, "_b", " + HALF"))
    return out


def source() -> str:
    """The module's text."""
    return HEADER + "\n".join(interleaved(body())) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if the checked-in module differs")
    parser.add_argument("--out", type=Path, default=TARGET, help="write the module here instead")
    args = parser.parse_args()
    text = source()
    if args.check:
        sys.exit(0 if TARGET.read_text() == text else 1)
    args.out.write_text(text)


if __name__ == "__main__":
    main()
