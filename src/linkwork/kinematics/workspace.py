"""The flattened mechanism the compiled kernels read, with scratch arrays for one evaluation at a time."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.jit import Backend, select_backend
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances

Array = NDArray[np.float64]


@dataclass
class Workspace:
    """The flattened mechanism and scratch arrays the compiled kernels need.

    ``twists``, ``loop_joint``, ``loop_sign``, ``loop_ptr``, ``rows`` and ``groups`` are the read-only arrays of
    :attr:`Mechanism.kernel_arrays` (built once per mechanism), in the layout
    :func:`linkwork.kinematics.march.march` takes;
    ``q``, ``res`` and ``jac`` are overwritten by every :meth:`evaluate`. ``kernels`` is the implementation of
    the :mod:`~linkwork.kinematics.march` kernels to call (compiled, or the same functions as plain Python while
    the cache is cold), chosen once per trace by :func:`linkwork.kinematics.jit.select_backend`.
    """

    twists: Array
    loop_joint: NDArray[np.int64]
    loop_sign: NDArray[np.int64]
    loop_ptr: NDArray[np.int64]
    rows: NDArray[np.int64]
    groups: NDArray[np.int64]
    q: Array
    res: Array
    jac: Array
    kernels: Backend

    @classmethod
    def of(cls, mech: Mechanism, kernels: Backend | None = None) -> Workspace:
        """Scratch space for ``mech``, calling ``kernels`` (default: chosen now by
        :func:`~linkwork.kinematics.jit.select_backend`)."""
        twists, lj, ls, lp, rows, groups = mech.kernel_arrays
        return cls(
            twists=twists,
            loop_joint=lj,
            loop_sign=ls,
            loop_ptr=lp,
            rows=rows,
            groups=groups,
            q=np.empty(mech.n_joints),
            res=np.empty(mech.n_equations),
            jac=np.empty((mech.n_equations, mech.n_unknowns)),
            kernels=kernels if kernels is not None else select_backend(),
        )

    def kernel_arrays(
        self,
    ) -> tuple[
        Array, NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]
    ]:
        """The mechanism tuple every kernel takes (``twists`` ... ``groups``, :data:`~linkwork.kinematics.march.MECHANISM`)."""
        return self.twists, self.loop_joint, self.loop_sign, self.loop_ptr, self.rows, self.groups

    @staticmethod
    def corrector(tol: Tolerances) -> tuple[float, float, float, float, int]:
        """The corrector's settings tuple (:data:`~linkwork.kinematics.march.CORRECTOR`) of ``tol``."""
        return tol.closure, tol.exact, tol.roundoff, tol.truncate, tol.max_iter

    def evaluate(self, u: Array) -> tuple[float, Array, Array]:
        """Residual norm, residual and reduced Jacobian (copies) at ``u``."""
        r = self.kernels.evaluate(
            self.kernel_arrays(), np.ascontiguousarray(u, dtype=float), self.q, self.res, self.jac
        )
        return float(r), self.res.copy(), self.jac.copy()
