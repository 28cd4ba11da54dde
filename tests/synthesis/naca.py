"""NACA 4-digit airfoils from the published formulas, for tests (not part of linkwork).

Thickness (Jacobs, Ward & Pinkerton 1933; Abbott & von Doenhoff, *Theory of Wing Sections*, Sec. 6.4):
``y_t = 5 t (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 - 0.1036 x^4)`` (the ``-0.1036`` variant
closes the trailing edge); camber line ``y_c = m / p^2 (2 p x - x^2)`` for ``x < p``, ``m / (1 - p)^2 ((1 - 2 p)
+ 2 p x - x^2)`` beyond, with the thickness laid off normal to the camber line.
"""

from __future__ import annotations

import numpy as np


def naca4(code: str, chord: float = 1.0, n: int = 80, *, closed: bool = True) -> np.ndarray:
    """The outline of NACA ``code`` (e.g. ``"2412"``) of ``chord``, cosine-spaced with ``n`` stations.

    From the trailing edge over the upper surface to the leading edge and back along the lower surface; a
    ``closed`` outline returns to its first point (the trailing edge), an open one is the upper surface only,
    from the leading edge to the trailing edge.
    """
    m, p, t = int(code[0]) / 100.0, int(code[1]) / 10.0, int(code[2:]) / 100.0
    x = (1.0 - np.cos(np.linspace(0.0, np.pi, n))) / 2.0
    yt = 5.0 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    if m == 0.0:
        yc, slope = np.zeros_like(x), np.zeros_like(x)
    else:
        fore = x < p
        yc = np.where(
            fore, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * x - x**2)
        )
        slope = np.where(fore, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
    theta = np.arctan(slope)
    upper = np.column_stack([x - yt * np.sin(theta), yc + yt * np.cos(theta)])
    lower = np.column_stack([x + yt * np.sin(theta), yc - yt * np.cos(theta)])
    if not closed:
        return upper * chord
    outline = np.vstack([upper[::-1], lower[1:]])
    outline[-1] = outline[0]  # the -0.1036 thickness closes the trailing edge: make it exact
    return outline * chord
