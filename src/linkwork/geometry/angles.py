"""Angles on the circle: one wrapping convention for the whole of linkwork.

Every revolute angle that is compared, differenced or reported modulo a turn goes through :func:`wrap`, which
maps onto the half-open interval ``[-pi, pi)``. (Two conventions in one code base make equal angles compare
unequal at the seam.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

TURN = 2.0 * np.pi
"""One full turn, radians."""


def wrap(angle: ArrayLike) -> NDArray[np.float64]:
    """Angles (radians, any shape) brought into ``[-pi, pi)``."""
    a = np.asarray(angle, dtype=float)
    return (a + np.pi) % TURN - np.pi


def wrapped_difference(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """``a - b`` as the shortest signed turn, in ``[-pi, pi)`` (radians, broadcast)."""
    return wrap(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
