"""Every loop of a mechanism measured in one frame, the ground's: what the normalised ratio and the misfit read.

A loop's product is taken from its own first body. :meth:`Mechanism.from_joints` takes the fundamental cycles of
a breadth-first spanning tree rooted at the ground, each starting at the lowest common ancestor ``X`` of its
non-tree joint's bodies; so a loop that does not pass through the ground (a Watt six-bar held by its crank) has
its product ``L`` and its Jacobian columns ``s Ad(g) xi`` (Gan & Pellegrino 2006, Eq. (21)) in the frame of
``X``, which moves. With ``A`` the motion of the tree path from the ground to ``X`` (the pose of ``X``,
:func:`linkwork.kinematics.closure.body_poses`), the same loop taken from the ground is

    F = A L A^-1,   log F = Ad_A log L,   columns of F = Ad_A (columns of L),

the columns then being every joint's axis in the ground's frame at that configuration, whichever loop it is
read from. The tracer's rows do not need this (a row's singular values are those of the loops as written: the
trace's own Jacobian, :mod:`linkwork.kinematics.kernels`); what combines loops or takes one point for all of them
does: the hinge centre of the normalised Jacobian (:mod:`linkwork.kinematics.normalization`), the cycle metric
that makes the loops' rows orthonormal, and the misfit of :mod:`linkwork.studies` (its residual ``T log F`` and
weight ``T`` about that centre). Mixing frames made a Watt six-bar's normalised ratio change by 15 % and its
misfit by 12 % with the body held as the ground.

Here a loop that starts elsewhere is written as the loop conjugated by its tree path: the path's joints down
from the ground to ``X``, the loop, and the same joints back up with their signs reversed. Its product is then
``F`` itself, computed by the same compiled closure pass as any loop, and its columns are the exact derivative
``dF F^-1`` (at a closed configuration a path joint's two columns cancel; off it, in an imperfect mechanism, they
are the ``(I - Ad_F)`` term that the derivative of the conjugation adds). Nothing else changes: the loop-joint
incidence of the conjugated loops is the loops' own.

A mechanism of one loop keeps its loop's own frame (its product taken where it starts): there is no other loop
to share a frame with, every measure here is unchanged by a rigid change of frame, and the Monte Carlo's
one-loop solve keeps its cost.
"""

from __future__ import annotations

import numpy as np

from linkwork.kinematics.closure import body_tree
from linkwork.kinematics.jit import Backend, select_backend
from linkwork.kinematics.mechanism import Array, IntArray, Loop, Mechanism


def loop_start(mech: Mechanism, loop: Loop) -> str | None:
    """The body a loop's product starts from: its first joint's ``before`` body (``after`` when the joint is
    traversed backwards); None without bodies."""
    if not loop.joints or len(mech.joint_bodies) != mech.n_joints:
        return None
    before, after = mech.joint_bodies[loop.joints[0]]
    return before if loop.signs[0] > 0 else after


def ground_frame_loops(mech: Mechanism) -> tuple[Loop, ...]:
    """``mech.loops``, each taken from the ground (see the module docstring): a loop that starts at another body
    ``X`` becomes ``path + loop + reversed path`` with the path's signs reversed on the way back, the path being the
    tree path from the ground to ``X`` (:func:`linkwork.kinematics.closure.body_tree`, the tree the loops came
    from). A mechanism of one loop, or without bodies, keeps its loops. Computed once per mechanism."""

    def build() -> tuple[Loop, ...]:
        if len(mech.loops) < 2 or len(mech.joint_bodies) != mech.n_joints or not mech.bodies:
            return mech.loops
        root, edges = body_tree(mech)
        down: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {root: ((), ())}
        for body, j, other, sign in edges:  # breadth first: a body's parent is reached before it
            joints, signs = down[body]
            down[other] = ((*joints, j), (*signs, sign))
        out = []
        for loop in mech.loops:
            start = loop_start(mech, loop)
            if start is None or start == root or start not in down:
                out.append(loop)
                continue
            joints, signs = down[start]
            out.append(
                Loop(
                    (*joints, *loop.joints, *reversed(joints)),
                    (*signs, *loop.signs, *(-s for s in reversed(signs))),
                )
            )
        return tuple(out)

    return mech.derived("ground frame loops", build)


def ground_frame_arrays(mech: Mechanism) -> tuple[IntArray, IntArray, IntArray]:
    """:func:`ground_frame_loops` flattened for the compiled kernels, as :meth:`Mechanism.loop_arrays` flattens
    ``mech.loops``: ``(joint, sign, ptr)``, loop ``k`` in ``ptr[k]:ptr[k+1]`` (new, writable arrays: the kernels
    that read them are compiled for those, ahead of time by ``linkwork compile``)."""
    loops = ground_frame_loops(mech)
    joints = np.array([j for loop in loops for j in loop.joints], dtype=np.int64)
    signs = np.array([s for loop in loops for s in loop.signs], dtype=np.int64)
    ptr = np.cumsum([0] + [len(loop.joints) for loop in loops]).astype(np.int64)
    return joints, signs, ptr


def member_loop(mech: Mechanism) -> IntArray:
    """``(n,)`` for every joint the first loop it belongs to (in ``mech.loops``; -1 for a joint in no loop): the
    loop its axis is read from (a joint on another loop's tree path only carries that loop to the ground)."""
    first = np.full(mech.n_joints, -1, dtype=np.int64)
    for k, loop in reversed(list(enumerate(mech.loops))):
        first[list(loop.joints)] = k
    return first


def ground_frame_closure(mech: Mechanism, q: Array, kernels: Backend | None = None) -> tuple[Array, Array]:
    """Every loop's residual ``log F`` ``(N, 6 * loops)`` and Jacobian columns ``(N, 6 * loops, n)`` (per joint,
    uncoupled, all six rows) in the ground's frame at displacements ``q (N, n)``: the loops of
    :func:`ground_frame_loops` through the compiled closure pass (``kernels``, default chosen now; a trace passes
    the backend it chose for the whole call)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    joints, signs, ptr = ground_frame_arrays(mech)
    n = mech.n_joints
    E = 6 * len(mech.loops)
    jac = np.zeros((len(q), E, n))
    residual = np.zeros((len(q), E))
    rows = np.arange(6, dtype=np.int64)
    groups = np.arange(n, dtype=np.int64)
    twists = np.ascontiguousarray(mech.twists)
    kernel = (kernels if kernels is not None else select_backend()).closure_jacobian
    for k, qk in enumerate(q):
        kernel((twists, joints, signs, ptr, rows, groups), np.ascontiguousarray(qk), n, residual[k], jac[k])
    return residual, jac


def joint_axes(mech: Mechanism, jac: Array) -> Array:
    """``(N, n, 6)`` every joint's axis in the ground's frame, read from the columns ``jac (N, 6 * loops, n)`` of
    :func:`ground_frame_closure` in the joint's :func:`member_loop` (its sign is the loop's; zero for a joint in no
    loop)."""
    N, _, n = jac.shape
    blocks = jac.reshape(N, len(mech.loops), 6, n)
    loop = member_loop(mech)
    axes = np.zeros((N, n, 6))
    inside = np.flatnonzero(loop >= 0)
    axes[:, inside, :] = blocks[:, loop[inside], :, inside].transpose(1, 0, 2)
    return axes
