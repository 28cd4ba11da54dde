"""M-segments (Sec. 3.3): one rigid shape, the mean of a segment's pieces on every profile.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (12)-(15), (21).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.fit import register

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MeanFit:
    """An M-segment fitted to ``p`` pieces of ``n`` points.

    Attributes
    ----------
    shape
        ``(n, 2)`` the mean segment ``Z_m`` in profile 1's frame (Eq. 14).
    instances
        ``(p, n, 2)`` the mean segment moved onto each profile's piece (Eq. 15).
    errors
        ``(p,)`` largest point-to-point distance per profile (Eq. 21).
    """

    shape: Array
    instances: Array
    errors: Array


def fit_mean_segment(pieces: ArrayLike) -> MeanFit:
    """Fit one M-segment to corresponding pieces ``(p, n, 2)`` of the ``p`` target profiles.

    Each piece is registered rigidly onto profile 1's piece (Eqs. 12, 13), corresponding points are
    averaged (Eq. 14), and the mean is registered back onto every piece (Eq. 15).
    """
    z = np.asarray(pieces, dtype=float)
    to_first = register(z, np.broadcast_to(z[0], z.shape))  # Eq. (12); profile 1 maps to itself
    shifted = to_first.apply(z)
    shifted[0] = z[0]
    mean = shifted.mean(axis=0)  # Eq. (14)
    back = register(np.broadcast_to(mean, z.shape), z)  # Eq. (15)
    instances = back.apply(np.broadcast_to(mean, z.shape))
    errors = np.sqrt(np.max(np.sum((instances - z) ** 2, axis=-1), axis=-1))  # Eq. (21)
    return MeanFit(shape=mean, instances=instances, errors=errors)
