"""The branch marcher: follows one branch after another with the compiled march and collects what it meets.

:class:`BranchMarcher` owns the growing result of a trace (points, located bifurcation points, folds of the
drive, branches) and the shared step budget. :meth:`BranchMarcher.run_branch` marches one branch to its end in
named steps: march a chunk (:meth:`~BranchMarcher.march_chunk`), cut it where it enters a higher-dimensional
component, record it, scan it for rank drops without a sign change and for folds of the drive, then handle the
stop code. :meth:`BranchMarcher.follow_queue` traces every branch queued at a bifurcation point (Sec. 6 of
Gan & Pellegrino 2006; branch switching after Kumar & Pellegrino 2000).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from linkwork import interrupts
from linkwork.geometry.angles import wrap
from linkwork.kinematics.bifurcation import correct_on_plane, locate, locate_minimum
from linkwork.kinematics.classify import classify_point, locate_fold
from linkwork.kinematics.jit import Backend
from linkwork.kinematics.march import MAX_CROSSINGS, MAX_PARTS, PART_SLACK
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances, numerical_rank, numerical_ranks
from linkwork.kinematics.stops import End, StopReason
from linkwork.kinematics.trace_result import Bifurcation, Branch, Fold, arclength_weights
from linkwork.kinematics.workspace import Workspace
from linkwork.progress import Progress

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MarchSettings:
    """What every march of one trace shares: the drive, the step control, the path's rank, limits, tolerances.

    ``target`` is the drive's target in the unknowns (``None``: none); ``lo``/``hi`` are the limits in the
    unknowns (``-inf``/``inf`` where none); ``periodic`` marks the revolute unknowns (compared modulo a turn);
    ``drive_joint`` is the joint the user drives (``-1``: the first joint of the drive's unknown), whose value a
    fold reports; ``weight`` each unknown's weight in the step's metric (1 for an angle, ``1 / L`` for a length,
    ``L`` the linkage's own length: steps the same in any length unit; ``None``: every weight 1).
    """

    drive: int
    target: float | None
    min_step: float
    max_step: float
    cos_turn: float
    r_path: int
    n_sigma: int
    periodic: NDArray[np.bool_]
    lo: Array
    hi: Array
    tol: Tolerances
    drive_joint: int = -1
    weight: Array | None = None


#: A closed path turning the drive towards a target further round stops when the whole cycles still needed, at
#: this fraction of the fewest steps a cycle took so far, are more than the steps left: cycles after the first
#: start at full step length and repeat it, so the margin only covers round-off in the step control.
CYCLE_SLACK = 0.9

#: Paper mode: the adaptive steps of each call of the probe that looks for a fold of the drive past a failed equal
#: step, and follows the path to the row's value (it goes on in such calls until it settles:
#: :meth:`BranchMarcher._follow_row`).
FOLD_PROBE_STEPS = 60

#: A fold of the drive is looked for only where its tangent component moves by more than this on one side: on a
#: branch along which the drive stays put (to round-off) that component only changes sign by noise.
FOLD_MOVING = 1e-8
#: Paper rows longer than ``max_step``: a local minimum of ``sigma_r / sigma_1`` lower than its higher neighbour by
#: more than this fraction is looked into for a rank drop (:meth:`BranchMarcher._scan_rank_minima`).
MINIMUM_DIP = 1e-6

#: A start whose unit tangent's drive component is below this is at a fold of the drive: the paper march cannot
#: take an equal drive step along it (march.predict's own bound), so its first row is reached by following the path
#: (:meth:`BranchMarcher._follow_row`), in the direction :func:`linkwork.kinematics.tracer.trace` chose.
FOLD_START = 1e-9

# A step over which the test function changes sign is taken again from its start in steps of 1/JUMP_SHRINK of its
# length, down to JUMP_LEVELS times: where the smaller steps follow the path without a sign change, the step had
# jumped across a narrow gap to another branch (next to an imperfect bifurcation, e.g. a four-bar a hair from
# Grashof's change point), and those steps replace it (BranchMarcher._jumped).
JUMP_SHRINK = 8.0
JUMP_LEVELS = 3
JUMP_RETRIES = 16  # steps taken again per branch: bounds the work


def leading_sign(tangent: Array, drive: int, moving: float = 1e-6) -> int:
    """+1 or -1: the sign of ``tangent``'s drive component, or, when that is below ``moving`` of its largest, of
    its first component that is not (round-off cannot flip it)."""
    size = float(np.max(np.abs(tangent)))
    for x in (tangent[drive], *tangent):
        if abs(x) > moving * size:
            return 1 if x > 0.0 else -1
    return 1


@dataclass
class Chunk:
    """The rows one call of the compiled march wrote (row 0 is its start), its stop code (a
    :class:`~linkwork.kinematics.stops.StopReason` value) and last step. ``s (count, 2)`` are the two arclengths
    of each row (``Trace.arclength``'s and the file units', :func:`~linkwork.kinematics.trace_result.
    arclength_weights`), each summed over every part of a step."""

    u: Array
    t: Array
    sigma: Array
    res: Array
    tau: Array
    s: Array
    count: int
    code: int
    h: float
    rank: NDArray[np.int64] | None = None  # each row's numerical rank, once the marcher has computed it
    # Paper mode: the brackets of the sign changes of the test function within the last row, part by part
    # (march.CROSSINGS: points, tangents, range bases before, count); None for an adaptive march.
    crossings: tuple[Array, Array, Array, NDArray[np.int64]] | None = None


@dataclass
class Rows:
    """Growing per-point storage, one block of rows per compiled march call (``rank``: each row's numerical rank,
    kept beside ``sigma`` when every block has it, else computed by the caller; ``s``: the two arclengths of each
    row, as :attr:`Chunk.s`)."""

    u: list[Array] = field(default_factory=list)
    sigma: list[Array] = field(default_factory=list)
    res: list[Array] = field(default_factory=list)
    tau: list[Array] = field(default_factory=list)
    s: list[Array] = field(default_factory=list)
    branch: list[NDArray[np.int64]] = field(default_factory=list)
    step: list[NDArray[np.int64]] = field(default_factory=list)
    rank: list[NDArray[np.int64]] = field(default_factory=list)

    def add_point(self, u: Array, sigma: Array, res: float, branch: int, rank: int) -> None:
        """Append one point (a bifurcation point opening a branch: arclength 0, step 0, test 0)."""
        self.rank.append(np.array([rank], dtype=np.int64))
        self.u.append(u[None, :].copy())
        self.sigma.append(sigma[None, :].copy())
        self.res.append(np.array([res]))
        self.tau.append(np.zeros(1))
        self.s.append(np.zeros((1, 2)))
        self.branch.append(np.array([branch], dtype=np.int64))
        self.step.append(np.zeros(1, dtype=np.int64))


@dataclass(frozen=True)
class Home:
    """What was measured at the point a branch's march began: a closed path's last row is that point again."""

    sigma: Array
    res: float
    tau: float

    def copy_to(self, chunk: Chunk, row: int) -> None:
        """Make ``chunk``'s row ``row`` (the start again, in continuous angles) carry the start's values: the
        compiled march copies its own row 0, which is the start only in a branch's first call."""
        chunk.sigma[row] = self.sigma
        chunk.res[row] = self.res
        chunk.tau[row] = self.tau


@dataclass
class QueuedBranch:
    """A branch to trace from a bifurcation point: its parent branch, the point and the direction to leave in."""

    parent: int
    bifurcation: int
    u: Array
    tangent: Array
    direction: int


PLAY_PROBE = 1e-6
PLAY_MARGIN = 100.0
"""The play an adaptive march that failed is probed with (:meth:`BranchMarcher._closure_floor`): a loop that closes
no better than this just ahead has met something else than rounded numbers. ``PLAY_MARGIN``: the play suggested
then, over the misfit met (rounded up to a power of ten)."""


class BranchMarcher:
    """Traces branches and collects their points, bifurcation points, folds and the branch graph."""

    def __init__(
        self,
        mech: Mechanism,
        settings: MarchSettings,
        max_steps: int,
        *,
        switch_branches: bool,
        progress: Progress | None = None,
        kernels: Backend | None = None,
        workspace: Workspace | None = None,
    ) -> None:
        self.mech = mech
        # The step metric's weights (writeable: the compiled march takes one array type)
        self.weight = (
            np.ones(len(settings.periodic)) if settings.weight is None else np.array(settings.weight)
        )
        # The weights of the two arclengths the rows carry (Chunk.s; writeable, as the weights above)
        self.measure = np.array(arclength_weights(mech))
        # The kernels the whole trace runs (chosen by its caller), in the caller's workspace when it has one.
        self.ws = workspace if workspace is not None else Workspace.of(mech, kernels)
        self.first_joint = mech.first_joints
        self.cfg = settings
        self.max_steps = max_steps
        self.budget = max_steps
        self.switch_branches = switch_branches
        self.progress = progress
        self.rows = Rows()
        self.found: list[Bifurcation] = []
        self.folds: list[Fold] = []
        self.branches: list[Branch] = []
        self.queue: list[QueuedBranch] = []
        self.max_misfit = 0.0
        self.spurious = 0
        self.arrivals: list[tuple[int, Array]] = []  # (point id, unit direction a traced branch arrived in)
        self.retraced = 0  # queued branches not traced: an arc already traced, run the other way
        self.interrupted = 0  # the signal that cut the trace short (0: none; see interrupts.held_signals)

    def stop_requested(self) -> bool:
        """Whether a signal held by the command line asks the trace to end now (noted in ``interrupted``)."""
        signum = interrupts.requested()
        if signum:
            self.interrupted = signum
        return bool(signum)

    # ---- one compiled call
    def march_chunk(
        self,
        u: Array,
        t: Array,
        u_home: Array,
        basis: Array,
        paper: bool,
        h0: float,
        n: int,
        check_closed: bool,
        reach: Array,
        before: Array | None = None,
        max_step: float | None = None,
        towards: float | None = None,
    ) -> Chunk:
        """March at most ``n`` steps from ``(u, t)`` with the compiled kernel (``basis`` updated in place; ``reach
        = [far, longest, t_home...]``: how far the path has gone from ``u_home``, its longest step and its
        tangent there, updated in place; ``before``: the row before ``u`` and its tangent, ``(2, m)``, when the
        call goes on with the path of the one before, so that the rows do not depend on where calls begin;
        ``max_step``: a cap below the settings' own, for :meth:`_jumped`'s probes; ``towards``: a drive value to
        land on instead of the trace's target, for :meth:`_follow_row`'s probe)."""
        cfg, tol, m = self.cfg, self.cfg.tol, len(u)
        out = Chunk(
            u=np.empty((n + 1, m)), t=np.empty((n + 1, m)), sigma=np.empty((n + 1, cfg.n_sigma)),
            res=np.empty(n + 1), tau=np.empty(n + 1), s=np.empty((n + 1, 2)), count=0, code=0, h=h0,
        )  # fmt: skip
        ws = self.ws
        target = cfg.target if towards is None else towards
        E, r = basis.shape
        crossings = (
            np.empty((MAX_CROSSINGS, 2, m)), np.empty((MAX_CROSSINGS, 2, m)), np.empty((MAX_CROSSINGS, E, r)),
            np.zeros(1, dtype=np.int64),
        )  # fmt: skip
        steps = (
            paper,
            cfg.drive,
            h0,
            cfg.min_step,
            cfg.max_step if max_step is None else max_step,
            cfg.cos_turn,
            0.0 if target is None else target,
            target is not None,
            tol.advance,
            tol.stall_steps,
            tol.stall_length,
            n,
            cfg.r_path,
            True,
            check_closed,
        )  # fmt: skip  (march.MARCH_ARGUMENTS["steps"])
        out.count, out.code, out.h = ws.kernels.march(
            ws.kernel_arrays(), (u, t, u_home, basis, reach, self._before(before, m)), steps, ws.corrector(tol), (cfg.periodic, cfg.lo, cfg.hi, self.weight, self.measure),
            (out.u, out.t, out.sigma, out.res, out.tau, out.s, crossings),
        )  # fmt: skip
        if paper:
            out.crossings = crossings
        return out

    def chords(self, u_a: Array, u_b: Array) -> Array:
        """``(2,)``: the chord from ``u_a`` to ``u_b`` in each of the two arclengths the rows carry (:attr:`Chunk.s`,
        the march's ``measure``), the increment of a step the march does not take in parts."""
        return np.asarray(np.linalg.norm((u_b - u_a) * self.measure, axis=1), dtype=float)

    @staticmethod
    def _before(before: Array | None, m: int) -> Array:
        """``before`` as the march takes it: ``(2, m)``, NaN where there is no row before the start."""
        return np.full((2, m), np.nan) if before is None else np.ascontiguousarray(before, dtype=float)

    # ---- one branch
    def run_branch(
        self,
        branch_id: int,
        u0: Array,
        t0: Array,
        basis: Array,
        *,
        paper: bool,
        h0: float,
        stop_at_known: bool,
        step_offset: int = 0,
        check_closed: bool = True,
        opened_at: tuple[Array, Home] | None = None,
    ) -> tuple[int, End]:
        """March one branch to its end, locating bifurcations and folds on the way; returns (steps, how it ended).

        ``step_offset``: step number of ``u0`` in its branch (1 when the branch opens at a bifurcation point).
        ``opened_at``: the point the branch's first row is, when it is not ``u0`` (the bifurcation point a queued
        branch leaves), with its values: the branch is closed when it comes back round to it.
        """
        n_steps, kind, text, about, point = self._march_branch(
            branch_id, u0, t0, basis, paper=paper, h0=h0, stop_at_known=stop_at_known,
            step_offset=step_offset, check_closed=check_closed, opened_at=opened_at,
        )  # fmt: skip
        if kind == StopReason.TARGET:
            self._target_onto_point()
        return n_steps, self.end(kind, text, self.rows.u[-1][-1], about, point)

    def end(
        self, kind: StopReason, text: str, u: Array, about: int | None = None, point: int | None = None
    ) -> End:
        """The :class:`End` of a branch whose last point is ``u``: ``about`` is the unknown the reason is about
        (``None``: the drive), reported as its first joint and that joint's value at ``u``."""
        g = self.cfg.drive if about is None else about
        j = self.first_joint[g]
        value = float(
            u[g] + self.mech.offsets[j]
        )  # the joint's value (angles_from_q of q_from_u, at joint j)
        return End(kind, text, self.mech.joint_names[j], value, point)

    def _march_branch(
        self,
        branch_id: int,
        u0: Array,
        t0: Array,
        basis: Array,
        *,
        paper: bool,
        h0: float,
        stop_at_known: bool,
        step_offset: int,
        check_closed: bool,
        opened_at: tuple[Array, Home] | None,
    ) -> tuple[int, StopReason, str, int | None, int | None]:
        """:meth:`run_branch`'s march: returns (steps, kind, text, the unknown the reason is about or ``None``
        for the drive, the located point it ended on or ``None``)."""
        u, t = u0.copy(), t0.copy()
        u_home = u0.copy() if opened_at is None else opened_at[0].copy()
        # how far the path has gone from u_home, its longest step and its tangent there (march.back_home)
        reach = np.zeros(2 + len(u0))
        home: Home | None = None if opened_at is None else opened_at[1]
        n_steps, first = 0, True
        jump_retries = 0  # steps taken again in smaller ones (see _jumped)
        before: Array | None = None  # the row before u when the march goes on with the last call's path
        # A drive turning round towards its target: the step its current cycle began at, the fewest steps a cycle
        # took, and paper mode's count of equal steps to the target.
        cycle_from, fewest = 0, 0
        target = self.cfg.target
        paper_steps = round(abs(target / h0)) if (paper and target is not None and h0 != 0.0) else 0
        # Back in Python every 100 steps when someone watches: a progress bar, or a held signal to end on.
        chunk_steps = 100 if (self.progress or interrupts.holding()) else self.budget
        while True:
            n = max(min(self.budget, chunk_steps), 0)
            if n <= 0 and not first:
                return n_steps, StopReason.BUDGET, StopReason.BUDGET.text, None, None
            signum = 0 if first else interrupts.requested()
            if signum:  # a SIGINT or SIGTERM held by the command line: end here, keeping every point marched
                self.interrupted = signum
                return n_steps, StopReason.INTERRUPTED, interrupts.stop_text(signum), None, None
            basis_prev = basis.copy()
            chunk = self.march_chunk(u, t, u_home, basis, paper, h0, n, check_closed, reach, before)
            before = None
            if chunk.code == StopReason.SIGN_CHANGE and not paper and jump_retries < JUMP_RETRIES:
                retaken = self._jumped(chunk, basis_prev, u_home, reach, check_closed)
                if retaken is not None:  # the last step had jumped to another branch: taken in smaller steps
                    jump_retries += 1
                    chunk = retaken
                    basis[:] = self._basis_before(
                        chunk.u[chunk.count - 1], chunk.t[chunk.count - 1], basis_prev
                    )
            home = home or Home(chunk.sigma[0].copy(), float(chunk.res[0]), float(chunk.tau[0]))
            if chunk.code == StopReason.CLOSED:
                home.copy_to(chunk, chunk.count - 1)
                target = self.cfg.target
                if (
                    target is not None
                    and self._target_on_last_step(chunk)
                    and self._land(chunk, self.cfg.drive, target)
                ):
                    chunk.code = (
                        StopReason.TARGET
                    )  # the closing step passed over the target (or ends on it): land there
            limit = self._land_on_limit(chunk) if chunk.code == StopReason.LIMIT else None
            ranks = numerical_ranks(
                chunk.sigma[: chunk.count], self.cfg.tol, self.ws.kernels.compiled
            )  # once
            chunk.rank = ranks
            component = self._component_entry(chunk, ranks)
            if component is not None:
                chunk.count = component + 1
            landed = self._landed_row(chunk, component, ranks)
            if (
                landed is not None
            ):  # a step landed on a singular point: the rows after it may be on another branch
                # A last row landed on the target keeps its code: a sign change there (the target on a crossing)
                # is the path's end, reached (it went on past the target, as from any landed row, to the budget).
                on_target = landed == chunk.count - 1 and self._on_target(chunk)
                if not on_target and (
                    landed < chunk.count - 1
                    or chunk.code not in (StopReason.TARGET, StopReason.CLOSED, StopReason.LIMIT)
                ):
                    chunk.count, chunk.code = landed + 1, StopReason.BUDGET
            self._record(chunk, branch_id, first, n_steps)
            base = n_steps + step_offset
            n_steps += chunk.count - 1
            self.budget -= chunk.count - 1
            through: Array | None = None
            if landed is not None:
                ended, through = self._on_landed(chunk, branch_id, base + landed, stop_at_known, paper)
                if ended is not None:
                    kind, text, point = ended
                    return n_steps, kind, text, None, point
            self._scan_rank_minima(chunk, branch_id, base, chunk.h if paper else 0.0)
            self._scan_folds(chunk, branch_id, base, first=first)
            first = False
            if self.progress:
                self.progress(self.max_steps - self.budget, self.max_steps)
            if component is not None:
                point, text = self._enter_component(chunk, branch_id, base + component)
                return n_steps, StopReason.COMPONENT, text, None, point
            if through is not None and chunk.code == StopReason.BUDGET and self.budget > 0:
                # Step off the singular point along the branch it was reached on, then march on from there.
                across = self._step_across(chunk, through, paper, basis_prev, basis)
                if across is None:
                    reason = "corrector failed at a fixed drive step" if paper else "corrector failed"
                    text = f"{reason} (leaving the bifurcation point the path landed on)"
                    return n_steps, StopReason.FAILED, text, None, None
                self._record(across, branch_id, False, n_steps)
                self._scan_folds(across, branch_id, n_steps + step_offset)
                n_steps += 1
                self.budget -= 1
                if across.code == StopReason.TARGET:
                    return n_steps, StopReason.TARGET, StopReason.TARGET.text, None, None
                u, t, h0 = across.u[1].copy(), across.t[1].copy(), across.h
                continue
            if chunk.code == StopReason.SIGN_CHANGE:
                known = self._on_sign_change(chunk, basis_prev, branch_id, n_steps + step_offset)
                if known is not None and stop_at_known:
                    self._end_on_known(chunk, known)
                    return n_steps, StopReason.KNOWN_POINT, f"reached bifurcation {known}", None, known
                if known is not None:  # through a known point and on: the arcs on both sides are traced
                    self._passed(known, chunk)
                if self._on_target(chunk):  # the step that changed sign had landed on the target: done (a
                    # target on a crossing is put onto the located point by run_branch, _target_onto_point)
                    return n_steps, StopReason.TARGET, StopReason.TARGET.text, None, None
            elif chunk.code == StopReason.CLOSED and self._turns_towards_target(chunk, u_home):
                # A full turn of the drive: the target is further round, unless the budget cannot go that far.
                cycle = n_steps - cycle_from
                fewest = cycle if fewest == 0 else min(fewest, cycle)
                beyond = self._target_beyond_budget(chunk, u_home, fewest)
                if beyond is not None:
                    return n_steps, StopReason.BUDGET, beyond, None, None
                u_home = chunk.u[chunk.count - 1].copy()
                reach[:] = 0.0
                cycle_from = n_steps
                if paper:  # the steps left evened out onto the target from the closing row
                    chunk.h = self._steps_onto_target(chunk, paper_steps - n_steps)
            elif (
                paper
                and self.budget > 0
                and (chunk.code == StopReason.FAILED or self._fold_start(chunk, n_steps))
            ):
                followed = self._follow_row(
                    chunk, basis, branch_id, n_steps + step_offset, from_fold=chunk.code == StopReason.TURNING
                )
                if followed is None:  # a fold of the drive before the step's value: its turning point
                    return n_steps, StopReason.TURNING, StopReason.TURNING.text, None, None
                if followed.count < 2:  # the path could not be followed to the row's value either
                    return n_steps, StopReason.FAILED, self._end_reason(chunk, paper), None, None
                # The row reached along the path, as the adaptive trace reaches it: recorded, and on from there.
                self._record(followed, branch_id, False, n_steps)
                n_steps += 1
                self.budget -= 1
                if self._on_target(followed):
                    return n_steps, StopReason.TARGET, StopReason.TARGET.text, None, None
                u, t, h0 = followed.u[1].copy(), followed.t[1].copy(), chunk.h
                before = np.array([followed.u[0], followed.t[0]])
                continue
            elif chunk.code != StopReason.BUDGET or self.budget <= 0:
                if limit is not None:
                    return n_steps, StopReason.LIMIT, limit[1], limit[0], None
                return n_steps, StopReason(chunk.code), self._end_reason(chunk, paper), None, None
            if self.budget <= 0:
                return n_steps, StopReason.BUDGET, StopReason.BUDGET.text, None, None
            u, t, h0 = chunk.u[chunk.count - 1].copy(), chunk.t[chunk.count - 1].copy(), chunk.h
            if chunk.count >= 2:  # the next call goes on with this path: its first step extrapolates as here
                before = np.array([chunk.u[chunk.count - 2], chunk.t[chunk.count - 2]])

    def _jumped(
        self, chunk: Chunk, basis_prev: Array, u_home: Array, reach: Array, check_closed: bool
    ) -> Chunk | None:
        """The chunk again with its last step taken in smaller ones, when that step jumped to another branch.

        Gan & Pellegrino's predictor-corrector (Sec. 4) lands wherever its corrector converges: next to an imperfect
        bifurcation (two branches a narrow gap apart, as where a four-bar is a hair from Grashof's change point) a
        step longer than the gap lands on the other branch, straight on, and the test function changes sign as at a
        true crossing, with no rank drop there. So the step over which the sign changed is taken again from its
        start in steps of an eighth of its length, never longer, over one and a half times its length; where the
        sign changes again, the step over which it did is taken again in the same way, :data:`JUMP_LEVELS` times
        (a step of 8^-3 = 1/512 of the first at the last). Where such smaller steps go on without a sign change,
        the step had jumped (the path turned away next to the crossing, where the step went straight on), and the
        chunk returned ends with the smaller steps instead; unless they came within ``Tolerances.loose`` of a rank
        drop (a true crossing, whose round-off gap small steps may turn through), or the path they follow, marched
        on in steps of an eighth of the jumped one, passes within a sixteenth of its length of where it landed (the
        same path: the test function's basis turned over on a long step, as on Goldberg's linkage moved or written
        in thousandths). A true crossing changes the sign at every step length. In each of these cases ``None``:
        the chunk stays as it was; so does a probe that ends for another reason (a target, a limit, a closed path),
        which the march meets again as it goes on.
        """
        c = chunk.count
        if c < 2 or self._known_on_step(chunk.u[c - 2], chunk.u[c - 1]) is not None:
            return None
        periodic, weight = self.cfg.periodic, self.weight

        def distance(x: Array, y: Array) -> Array:
            """Step-metric distances between the rows of ``x`` and ``y`` (revolute unknowns modulo a turn)."""
            diff = np.atleast_2d(x - y)
            diff[:, periodic] = wrap(diff[:, periodic])
            return np.asarray(np.linalg.norm(diff * weight, axis=1))

        u_b = chunk.u[c - 1]
        length = float(distance(u_b, chunk.u[c - 2])[0])
        u_a, t_a = chunk.u[c - 2].copy(), chunk.t[c - 2].copy()
        basis_a = self._basis_before(u_a, t_a, basis_prev)
        before = None if c < 3 else np.array([chunk.u[c - 3], chunk.t[c - 3]])
        kept: list[Chunk] = []  # the probes' rows before each sign change, then the probe that went through
        step = length
        for _ in range(JUMP_LEVELS):
            h = step / JUMP_SHRINK
            if h < 4.0 * self.cfg.min_step:
                return None
            basis_probe = basis_a.copy()
            probe = self.march_chunk(
                u_a, t_a, u_home, basis_probe, False, h, int(1.5 * JUMP_SHRINK) + 4, check_closed,
                reach.copy(), before, max_step=h,
            )  # fmt: skip
            changed = (probe.tau[1 : probe.count] * probe.tau[0] <= 0.0).nonzero()[0]  # its own sign
            if len(changed) == 0 and probe.code != StopReason.SIGN_CHANGE:
                if probe.code != StopReason.BUDGET:
                    return None
                kept.append(probe)
                if self._singular_on(kept):
                    return None  # they pass through a rank drop: a crossing, which the sign change locates
                # On along the path, in steps of an eighth of the jumped one: the same path passes where it landed.
                m = probe.count - 1
                on = self.march_chunk(
                    probe.u[m].copy(), probe.t[m].copy(), u_home, basis_probe, False, length / JUMP_SHRINK,
                    int(1.5 * JUMP_SHRINK) + 4, False, reach.copy(),
                    None if m < 1 else np.array([probe.u[m - 1], probe.t[m - 1]]), max_step=length / JUMP_SHRINK,
                )  # fmt: skip
                passed = min(float(distance(p.u[: p.count], u_b).min()) for p in [*kept, on])
                if passed < length / (2.0 * JUMP_SHRINK):
                    return None  # the same path: the sign change was the test function's, not a jump
                return self._retaken(chunk, kept, h)
            j = int(changed[0]) if len(changed) else probe.count - 2  # the last row before the sign change
            if j < 0:
                return None
            probe.count = j + 1
            kept.append(probe)
            step = float(distance(probe.u[j + 1], probe.u[j])[0])
            if j >= 1:
                before = np.array([probe.u[j - 1], probe.t[j - 1]])
                basis_a = self._basis_before(probe.u[j], probe.t[j], basis_a)
            u_a, t_a = probe.u[j].copy(), probe.t[j].copy()
        return None

    def _singular_on(self, probes: list[Chunk]) -> bool:
        """Whether the probes' rows come within ``Tolerances.loose`` of a rank drop (``sigma_r / sigma_1``).

        Next to a true crossing small steps turn onto the other branch too, where the corrector's round-off
        leaves the crossing a gap of its own size; a path that came that close to a singular point meets a point
        the tracer locates and reports (:meth:`_scan_rank_minima` classifies the same ratio), not a gap."""
        r = self.cfg.r_path
        if r < 1:
            return False
        ratios = [p.sigma[: p.count, r - 1] / p.sigma[: p.count, 0] for p in probes if p.count > 0]
        return bool(ratios) and float(np.min(np.concatenate(ratios))) <= self.cfg.tol.loose

    @staticmethod
    def _retaken(chunk: Chunk, probes: list[Chunk], h: float) -> Chunk:
        """``chunk`` without its last row, then the rows of each probe after its first (see :meth:`_jumped`)."""
        k = chunk.count - 1
        parts = [(chunk, 0, k)] + [(p, 1, p.count) for p in probes]
        s, base = [], np.zeros(2)
        for i, (part, lo, hi) in enumerate(parts):
            s.append(part.s[lo:hi] - (0.0 if i == 0 else part.s[0]) + base)
            base = s[-1][-1] if hi > lo else base
        return Chunk(
            u=np.concatenate([p.u[lo:hi] for p, lo, hi in parts]),
            t=np.concatenate([p.t[lo:hi] for p, lo, hi in parts]),
            sigma=np.concatenate([p.sigma[lo:hi] for p, lo, hi in parts]),
            res=np.concatenate([p.res[lo:hi] for p, lo, hi in parts]),
            tau=np.concatenate([p.tau[lo:hi] for p, lo, hi in parts]),
            s=np.concatenate(s), count=k + sum(p.count - 1 for p in probes), code=int(StopReason.BUDGET), h=h,
        )  # fmt: skip

    def _land_on_limit(self, chunk: Chunk) -> tuple[int, str]:
        """Replace the chunk's last row (past a limit) by the point of the step where the joint is at its limit.

        From the row before it, the predictor goes along the tangent to the limit's value and the corrector
        holds that unknown there (as when landing on a target), so a branch ends exactly on the limit. Returns
        the unknown that passed its limit first and the end reason, ``limit <joint>``.
        """
        cfg, c = self.cfg, chunk.count
        u_b = chunk.u[c - 1]
        over = np.flatnonzero((u_b < cfg.lo) | (u_b > cfg.hi))
        reason = "limit " + ", ".join(self.mech.joint_names[self.first_joint[g]] for g in over)
        g = int(over[0])
        self._land(chunk, g, cfg.lo[g] if u_b[g] < cfg.lo[g] else cfg.hi[g])
        return g, reason

    def _landed_row(self, chunk: Chunk, component: int | None, ranks: NDArray[np.int64]) -> int | None:
        """The first row after the chunk's start where the Jacobian's rank has dropped below the path's, unless
        it is where the branch enters a higher-dimensional component: a step that landed on a singular point
        (equal drive steps landing on a bifurcation point), where the march's tangent is any vector of a null
        space of dimension two and the sign of the test function means nothing. ``ranks``: the rank of each row
        of the chunk (as the march returned it)."""
        if chunk.count < 2:
            return None
        low = np.flatnonzero(ranks[1 : chunk.count] < self.cfg.r_path)
        if len(low) == 0:
            return None
        row = int(low[0]) + 1
        return None if component is not None and row >= component else row

    def _on_landed(
        self, chunk: Chunk, branch_id: int, step: int, stop_at_known: bool, paper: bool
    ) -> tuple[tuple[StopReason, str, int] | None, Array | None]:
        """Recognise the chunk's last row, a singular point the path landed on, as a located point.

        A new point is classified and kept (its other branches queued); a known one ends a branch that stops at
        known points. Returns ``((kind, text, point) of the branch's end, or None; tangent to go on along)``: the branch tangent there nearest
        the incoming one (or the incoming tangent projected on the null space when there are fewer than two),
        oriented the same way; it replaces the row's tangent.

        The incoming tangent is the one the step came in with: an adaptive step's, the row before's; a paper
        row's, the row's own (the march keeps at a row landed on a singular point the tangent of its last part,
        or closing part: the row before is a whole row back, 345 deg of the drive along a long row, where the
        path's tangent is another)."""
        c = chunk.count
        u_k, t_in = chunk.u[c - 1].copy(), chunk.t[c - 1 if paper else c - 2].copy()
        known = self._match(u_k)
        if known is None:
            point = classify_point(self.mech, self.ws, len(self.found), branch_id, step, u_k, 0.0, self.cfg)
            self._add_point(point, branch_id, t_in)
        else:
            point = self.found[known]
            if stop_at_known:
                self._arrived(known, u_k - chunk.u[c - 2])
                return (StopReason.KNOWN_POINT, f"reached bifurcation {known}", known), None
            self._passed(known, chunk)
        if point.kind == "component" and not self._crosses(chunk, c - 1):
            dim = point.dimension
            text = f"entered a {dim}-dimensional component (mobility {dim}) at point {point.id}"
            return (StopReason.COMPONENT, text, point.id), None
        self._onto_point(chunk, c - 1, point)
        u_k = chunk.u[c - 1].copy()
        if len(point.tangents_u) >= 2:
            tangent = point.tangents_u[int(np.argmax(np.abs(point.tangents_u @ t_in)))].copy()
        else:
            _, _, jac = self.ws.evaluate(u_k)
            _, s, Vt = np.linalg.svd(jac)
            null = Vt[numerical_rank(s, self.cfg.tol) :]
            tangent = null.T @ (null @ t_in)
        tangent /= np.linalg.norm(tangent)
        tangent *= 1.0 if tangent @ t_in >= 0.0 else -1.0
        chunk.t[c - 1] = tangent
        return None, tangent

    def _crosses(self, chunk: Chunk, row: int) -> bool:
        """Whether the path, landed on a point of a higher-dimensional component at the chunk's row ``row``,
        crosses it rather than entering it: the row before it has the path's rank (mobility 1), so the step
        landed on a single singular point of the path (equal drive steps landing on Sarrus's folded
        configuration, where a two-dimensional component meets the path), which the branch passes through as
        the adaptive trace does, along the incoming tangent projected on the null space there. A branch enters
        a component where :attr:`Tolerances.component_points` rows in a row have mobility 2 or more
        (:meth:`_component_entry`), and a path that lands on one again from a singular row ends there."""
        if row < 1:
            return False
        ranks = chunk.rank
        if ranks is None:
            ranks = numerical_ranks(chunk.sigma[: chunk.count], self.cfg.tol, self.ws.kernels.compiled)
        return bool(ranks[row - 1] >= self.cfg.r_path)

    def _onto_point(self, chunk: Chunk, row: int, point: Bifurcation) -> None:
        """Put the chunk's row ``row``, a step that landed on the singular point ``point``, onto the located point.

        The corrector that landed there held the drive at its step's value and stopped at a closure residual of
        ``Tolerances.exact``, which on a double point leaves the other joints only as close as its square root (a
        change-point four-bar's paper-mode row at its crossing was 3.8e-5 deg off the closed form); the located
        point is polished to about 1e-11 rad (docs/tracing.md, Polishing). The row takes the point's unknowns,
        residual and singular values when it has the point's drive value to round-off (paper mode's equal step,
        kept exactly), or to the point's own accuracy (``bracket``: a point polished from a row 7.7e-11 rad off it
        had its drive 2.1e-12 rad off, 1.5e-11 its accuracy), and lies within ``Tolerances.loose`` of it; the row
        already recorded is changed too. A point met again whole turns of its periodic unknowns on is the same
        point there (a parallelogram's crossing at 720 deg was left 1.2e-4 deg off).
        """
        if not 0 <= row < chunk.count:
            return
        u_k = chunk.u[row].copy()
        snapped = self._snapped(u_k, point)
        if snapped is None:
            return
        chunk.u[row] = snapped
        chunk.sigma[row] = point.sigma
        chunk.res[row] = point.residual
        rows = self.rows
        if rows.u:
            same = np.flatnonzero(np.all(rows.u[-1] == u_k, axis=1))
            for i in same[-1:].tolist():
                rows.u[-1][i] = snapped
                rows.sigma[-1][i] = point.sigma
                rows.res[-1][i] = point.residual

    def _step_across(
        self, chunk: Chunk, tangent: Array, paper: bool, basis_prev: Array, basis: Array
    ) -> Chunk | None:
        """One step from the chunk's last row (a singular point) along ``tangent``: a two-row chunk (that row,
        then the new point with its tangent, singular values, residual and test value), ``basis`` updated in place
        for the march that goes on; None when the corrector does not converge.

        Paper mode moves the drive by the fixed step with the drive held, as the march does, in the march's parts
        (no longer than ``max_step`` each, the tangent taken again after each: one linear prediction over a row of
        172 deg landed a whole turn of the coupler off); adaptive mode takes the march's step length along the
        tangent and corrects in the hyperplane normal to it, halving the step on failure. A target on the step is
        landed on (code ``TARGET``)."""
        cfg, ws, tol = self.cfg, self.ws, self.cfg.tol
        c, d = chunk.count, cfg.drive
        u_k = chunk.u[c - 1]
        h = chunk.h
        u_next: Array | None = None
        s_next = np.zeros(2)  # the step's two arclengths (Chunk.s)
        on_target = False
        while u_next is None and abs(h) >= cfg.min_step:
            if paper:
                row = self._paper_row_from(u_k, tangent, h, basis_prev)
                if row is None:
                    return None
                u_next, s_next = row
                on_target = cfg.target is not None and float(u_next[d]) == cfg.target
            else:
                guess, _, ok = correct_on_plane(ws, u_k + h * tangent, tangent, tol)
                if ok and float(tangent @ (guess - u_k)) > tol.advance * h:
                    u_next, s_next = guess, self.chords(u_k, guess)
                else:
                    h *= 0.5
        if u_next is None:
            return None
        r, _, jac = ws.evaluate(u_next)
        t_next, sigma = np.empty_like(tangent), np.empty(cfg.n_sigma)
        new_basis = basis_prev.copy()
        tau = ws.kernels.tangent_and_test(
            jac, tangent.copy(), new_basis, cfg.r_path, t_next, sigma, self.weight
        )
        basis[:, :] = new_basis
        across = Chunk(
            u=np.array([u_k, u_next]), t=np.array([tangent, t_next]),
            sigma=np.array([chunk.sigma[c - 1], sigma]), res=np.array([chunk.res[c - 1], r]),
            tau=np.array([chunk.tau[c - 1], tau]), s=np.array([np.zeros(2), s_next]),
            count=2, code=StopReason.BUDGET, h=h,
        )  # fmt: skip
        if on_target or (
            not paper
            and cfg.target is not None
            and self._target_on_last_step(across)
            and self._land(across, d, cfg.target)
        ):
            across.code = StopReason.TARGET
        return across

    def _snapped(self, u_k: Array, point: Bifurcation) -> Array | None:
        """``u_k`` put onto the located ``point`` (:meth:`_onto_point`'s test: the drive's value the same to
        round-off or the point's accuracy, within ``Tolerances.loose``; the point met again whole turns of its
        periodic unknowns on is the same point there), or ``None``."""
        d = self.cfg.drive
        u_p = np.asarray(point.u, dtype=float)
        if point.kind != "bifurcation" or u_p.shape != u_k.shape:
            return None
        turn = 2.0 * np.pi  # (a crank's crossing at 720 deg is the one located at 360)
        u_p = u_p + np.where(self.cfg.periodic, np.round((u_k - u_p) / turn) * turn, 0.0)
        drive_off = abs(float(u_p[d] - u_k[d]))
        on_drive = max(1e-12 * max(1.0, abs(float(u_k[d]))), float(point.bracket))
        if drive_off > on_drive or np.linalg.norm(u_p - u_k) > self.cfg.tol.loose:
            return None
        snapped = u_p.copy()
        snapped[d] = u_k[d]
        return snapped

    def _target_onto_point(self) -> None:
        """A branch that ended on its target: its last row (the last recorded) onto a located point there, if
        any (:meth:`_snapped`): a target on a crossing, reached by a step the corrector closed with the drive held,
        is the point to its own accuracy, not to the square root of the closure residual (a deltoid's adaptive
        trace to its crossing at 360 deg was 4.5e-5 deg off)."""
        rows = self.rows
        if not rows.u or len(rows.u[-1]) == 0:
            return
        u_k = np.asarray(rows.u[-1][-1], dtype=float).copy()
        for located in self.found:
            snapped = self._snapped(u_k, located)
            if snapped is not None:
                rows.u[-1][-1] = snapped
                rows.sigma[-1][-1] = located.sigma
                rows.res[-1][-1] = located.residual
                return

    def _paper_row_from(
        self, u_k: Array, tangent: Array, h: float, basis_prev: Array
    ) -> tuple[Array, Array] | None:
        """Paper mode: the row one equal drive step ``h`` on from the singular point ``u_k``, along ``tangent``
        (the branch it was reached on), marched as every paper row is, by one call of the compiled march for one
        row: it keeps ``tangent`` at its singular start, and takes the row in parts no longer than ``max_step``
        shifted off round drive values, a part that turns next to a singular point again in more, the row's own
        value approached again in closing parts, and lands on the target when the row's value is that to
        ``1e-9`` (equal parts from a row 1e-6 deg short of a crossing at 180 deg had one land 2e-4 deg short of
        the next crossing, unjudged, and go on along the other branch). ``basis_prev``: the range basis the
        orientation follows (not changed). ``None`` when the tangent does not move the drive towards ``h``, the
        drive turns back, or the march fails."""
        d = self.cfg.drive
        if tangent[d] * h <= 0.0 or abs(tangent[d]) < 1e-12:
            return None
        row = self.march_chunk(
            u_k.copy(),
            tangent.copy(),
            u_k.copy(),
            basis_prev.copy(),
            True,
            h,
            1,
            False,
            np.zeros(2 + len(u_k)),
        )
        if row.count < 2 or row.code in (StopReason.FAILED, StopReason.TURNING):
            return None
        return row.u[1].copy(), row.s[1].copy()

    def _on_target(self, chunk: Chunk) -> bool:
        """Whether the chunk's last row is on the drive's target (a step that lands there holds the drive at the
        target exactly)."""
        target = self.cfg.target
        return target is not None and float(chunk.u[chunk.count - 1, self.cfg.drive]) == target

    def _target_on_last_step(self, chunk: Chunk) -> bool:
        """Whether the drive's target lies on the chunk's last step (between its last two rows' drive values).

        A path closes by snapping onto its start once it is within one and a half steps of it; a target on that
        stretch (just below a full turn of the drive, or exactly on it) is reached there, not refused."""
        cfg, c = self.cfg, chunk.count
        if cfg.target is None or c < 2:
            return False
        a, b = chunk.u[c - 2, cfg.drive], chunk.u[c - 1, cfg.drive]
        slack = 1e-12 * max(1.0, abs(cfg.target))
        return min(a, b) - slack <= cfg.target <= max(a, b) + slack

    def _land(self, chunk: Chunk, g: int, value: float) -> bool:
        """Replace the chunk's last row by the point of its last step where unknown ``g`` is at ``value``.

        From the row before it, the predictor goes along the tangent to that value and the corrector holds the
        unknown there (as when landing on a target). Returns whether it converged (the row is kept otherwise).
        """
        cfg, c = self.cfg, chunk.count
        u_a, t_a = chunk.u[c - 2], chunk.t[c - 2]
        if abs(t_a[g]) < 1e-12:
            return False
        guess = u_a + (value - u_a[g]) / t_a[g] * t_a
        guess[g] = value
        tol, ws = cfg.tol, self.ws
        ok, _, r = ws.kernels.correct(ws.kernel_arrays(), guess, g, ws.corrector(tol), ws.q, ws.res, ws.jac)
        if not ok:
            return False
        _, _, jac = ws.evaluate(guess)
        chunk.u[c - 1] = guess
        chunk.sigma[c - 1] = np.linalg.svd(jac, compute_uv=False)[: cfg.n_sigma]
        chunk.res[c - 1] = r
        chunk.s[c - 1] = chunk.s[c - 2] + self._landing_arclengths(u_a, t_a, g, guess)
        return True

    def _landing_arclengths(self, u_a: Array, t_a: Array, g: int, u_b: Array) -> Array:
        """The two arclengths (:attr:`Chunk.s`) of the path from ``u_a`` (tangent ``t_a``) to the point ``u_b``
        landed on with unknown ``g`` held (:meth:`_land`): the chord when it is no longer than ``max_step`` in the
        step's metric (an adaptive step), else the chords of parts no longer than that, as the march sums a long
        paper row's (``g`` held at equal parts of its change, each predicted along the tangent at the part before
        and corrected; the null vector of the Jacobian taken again after each). The chord again where a part
        fails or the parts end elsewhere than ``u_b`` (another branch)."""
        cfg, ws, tol = self.cfg, self.ws, self.cfg.tol
        chord = self.chords(u_a, u_b)
        length = float(np.linalg.norm((u_b - u_a) * self.weight))
        parts = min(MAX_PARTS, max(1, math.ceil(length / cfg.max_step - PART_SLACK)))
        if parts == 1:
            return chord
        u, t, s = u_a.copy(), t_a.copy(), np.zeros(2)
        for i in range(1, parts + 1):
            if abs(t[g]) < 1e-12:
                return chord
            goal = float(u_b[g]) if i == parts else float(u_a[g] + (u_b[g] - u_a[g]) * i / parts)
            guess = u + ((goal - u[g]) / t[g]) * t
            guess[g] = goal
            ok, _, _ = ws.kernels.correct(
                ws.kernel_arrays(), guess, g, ws.corrector(tol), ws.q, ws.res, ws.jac
            )
            if not ok or np.any(np.abs((guess - u)[cfg.periodic]) > 0.5 * np.pi):
                return chord
            _, _, jac = ws.evaluate(guess)
            t_next = np.linalg.svd(jac)[2][-1]
            t = t_next if float(t_next @ t) > 0.0 else -t_next
            s += self.chords(u, guess)
            u = guess
        return s if float(np.linalg.norm((u - u_b) * self.weight)) <= tol.loose else chord

    def _turns_towards_target(self, chunk: Chunk, u_home: Array) -> bool:
        """Whether a closed path turned the (revolute) drive by whole turns towards a target still ahead."""
        cfg, d = self.cfg, self.cfg.drive
        if cfg.target is None or not cfg.periodic[d]:
            return False
        now = chunk.u[chunk.count - 1, d]
        turned = now - u_home[d]
        return abs(turned) > np.pi and (cfg.target - now) * turned > 0.0

    def _steps_onto_target(self, chunk: Chunk, left: int) -> float:
        """Paper mode, after a closed cycle of a drive turning towards its target: the equal drive step that lands
        on the target from the chunk's last row in the ``left`` steps the paper's count leaves (at least one). A
        paper path closes by landing on its start, whose row is then the start itself (the running sum's rounding
        dropped): the steps after it are evened out again from there, so that the last lands on the target."""
        target = self.cfg.target
        if target is None:
            return chunk.h
        to_go = target - float(chunk.u[chunk.count - 1, self.cfg.drive])
        return to_go / max(1, left)

    def _target_beyond_budget(self, chunk: Chunk, u_home: Array, cycle_steps: int) -> str | None:
        """Why the target cannot be reached with the steps left, when a closed path (the chunk's last row back at
        ``u_home``, the drive turned by whole turns towards the target) shows it: every further cycle turns the
        drive as this one did and takes at least about ``cycle_steps`` steps (the fewest a cycle took so far), so
        the whole cycles still needed, at :data:`CYCLE_SLACK` of those steps each, are more than the budget left.
        ``None`` when the target may still be reached (the march goes round again)."""
        cfg, d = self.cfg, self.cfg.drive
        target = cfg.target
        if target is None or cycle_steps <= 0:
            return None
        now = float(chunk.u[chunk.count - 1, d])
        turned = now - float(u_home[d])
        cycles = (target - now) / turned  # positive: the path turns towards the target
        needed = math.floor(cycles) * float(cycle_steps)
        if needed * CYCLE_SLACK <= self.budget:
            return None
        j = cfg.drive_joint if cfg.drive_joint >= 0 else self.first_joint[d]
        name = self.mech.joint_names[j]
        per_cycle = (
            f"{np.degrees(abs(turned)):.2f} deg" if self.mech.joint_types[j] == "R" else f"{abs(turned):.6g}"
        )
        return (
            f"step budget: {cycles:.3g} more cycles of the path to go (about {needed:.3g} steps; one cycle took "
            f"{cycle_steps} steps and turns {name} by {per_cycle}), {self.budget} of {self.max_steps} steps left"
        )

    def _fold_start(self, chunk: Chunk, n_steps: int) -> bool:
        """Paper mode: whether the chunk is the branch's first, stopped as a turning point before any step because
        its start is a fold of the drive (the drive's tangent component below :data:`FOLD_START`), from which the
        first equal step is followed along the path instead (:meth:`_follow_row`)."""
        return (
            n_steps == 0
            and chunk.count == 1
            and chunk.code == StopReason.TURNING
            and abs(float(chunk.t[0, self.cfg.drive])) < FOLD_START * float(np.linalg.norm(chunk.t[0]))
        )

    def _follow_row(
        self, chunk: Chunk, basis: Array, branch_id: int, step: int, from_fold: bool = False
    ) -> Chunk | None:
        """Paper mode, the chunk's last equal drive step failed (in every number of parts): the row it asked for,
        reached by following the path adaptively (arclength steps, as an adaptive trace does) from the last row up
        to the row's drive value and landing on it exactly; ``None`` when a fold of the drive lies before that
        value (equal drive steps cannot go on: the fold is located and recorded, the branch's turning point).

        Equal parts of the drive fail where the drive nearly stops: a Goldberg 5R's other joints turn up to 435
        times as fast as its drive there, so that even a part of 1/1,311 of an 80 deg step moves them 26 deg, far
        beyond what the tangent's prediction and the corrector with the drive held can follow, though the path
        is smooth and an adaptive trace follows it. The probe's steps are arclength steps of at most ``max_step``,
        towards larger drive values for a positive step; it goes on in calls of :data:`FOLD_PROBE_STEPS` steps,
        locating on the way every sign change of the test function (:meth:`_on_sign_change`: the bifurcation
        points the row passes are reported and their branches queued, as the march does) and the rank drops
        without one, until it lands on the row's value (returned: a two-row chunk, the last row and the landed
        one with its tangent, singular values, residual, test value and arclength; ``basis`` updated in place for
        the march that goes on), the drive turns back (the fold, recorded at step ``step``, if it is short of the
        value asked for), or it ends otherwise, comes back round to the row it left, or has taken as many steps
        as the trace has left (a chunk of one row: the step failed). The probe's own rows are not kept: the rows
        of a paper trace are its equal drive steps.

        ``from_fold``: the last row is the branch's start, at a fold of the drive (:meth:`_fold_start`): the probe
        leaves along the start's tangent as oriented (the drive moves the same way either way), and the start is
        not a fold the probe meets; ``None`` (a turning point) when the drive moves away from the row's value.
        """
        cfg, d, c = self.cfg, self.cfg.drive, chunk.count - 1
        failed = Chunk(
            u=chunk.u[c : c + 1].copy(), t=chunk.t[c : c + 1].copy(), sigma=chunk.sigma[c : c + 1].copy(),
            res=chunk.res[c : c + 1].copy(), tau=chunk.tau[c : c + 1].copy(), s=np.zeros((1, 2)), count=1,
            code=int(StopReason.FAILED), h=chunk.h,
        )  # fmt: skip
        if c < 0 or chunk.h == 0.0:
            return failed
        u, t = chunk.u[c].copy(), chunk.t[c].copy()
        if t[d] * chunk.h < 0.0 and not from_fold:
            t = -t
        u_start, sign, asked = u.copy(), float(np.sign(chunk.h)), abs(chunk.h)
        value = float(u_start[d] + chunk.h)  # the row's drive value, as the march computes it
        if cfg.target is not None and abs(value - cfg.target) < 1e-9 * max(1.0, abs(cfg.target)):
            value = cfg.target
        h = min(cfg.max_step, asked) / 4.0
        basis_probe, reach = basis.copy(), np.zeros(2 + len(u))
        before: Array | None = None
        s_total = np.zeros(2)
        left = max(self.budget, FOLD_PROBE_STEPS)  # one call at least, else the steps the trace has left
        while True:
            basis_prev = basis_probe.copy()
            probe = self.march_chunk(
                u, t, u_start, basis_probe, False, h, min(FOLD_PROBE_STEPS, left), True, reach, before,
                towards=value,
            )  # fmt: skip
            left -= probe.count - 1
            td = probe.t[: probe.count, d].copy()
            if from_fold:  # the start: a fold of the drive, its tangent component round-off
                if probe.count >= 2 and sign * (probe.u[1, d] - u_start[d]) < 0.0:
                    return (
                        None  # the drive moves away from the row's value either way: the start turns it back
                    )
                td[0], from_fold = 0.0, False
            turned = (td[:-1] * td[1:] < 0.0).nonzero()[0]
            if len(turned) > 0:  # the drive turns back before the row's value (where the probe would land)
                k = int(turned[0])
                if float(np.max(sign * (probe.u[k : k + 2, d] - u_start[d]))) >= asked:
                    return failed  # beyond the row's value, which the probe passed without landing on it
                probe.count = k + 2  # the fold's step only
                folds = len(self.folds)
                self._scan_folds(probe, branch_id, step, at=step)
                return None if len(self.folds) > folds else failed
            if float(np.max(sign * (probe.u[: probe.count, d] - u_start[d]))) > asked:
                return failed  # the drive passed the row's value without landing on it
            self._scan_rank_minima(probe, branch_id, step)
            if probe.code == StopReason.SIGN_CHANGE:
                known = self._on_sign_change(probe, basis_prev, branch_id, step)
                if known is not None:
                    self._passed(known, probe)
            s_total += probe.s[probe.count - 1]
            last = probe.count - 1
            if probe.code in (StopReason.TARGET, StopReason.SIGN_CHANGE) and probe.u[last, d] == value:
                break  # landed on the row's value (a sign change on the landing step was located above)
            if probe.code not in (StopReason.BUDGET, StopReason.SIGN_CHANGE) or probe.count < 2 or left <= 0:
                return failed  # closed, failed, at a limit, or out of steps: the row is not reached
            u, t, h = probe.u[last].copy(), probe.t[last].copy(), probe.h
            before = np.array([probe.u[last - 1], probe.t[last - 1]])
        basis[:, :] = basis_probe
        return Chunk(
            u=np.array([chunk.u[c], probe.u[last]]), t=np.array([chunk.t[c], probe.t[last]]),
            sigma=np.array([chunk.sigma[c], probe.sigma[last]]), res=np.array([chunk.res[c], probe.res[last]]),
            tau=np.array([chunk.tau[c], probe.tau[last]]), s=np.array([np.zeros(2), s_total]), count=2,
            code=int(StopReason.BUDGET), h=chunk.h,
        )  # fmt: skip

    def _end_reason(self, chunk: Chunk, paper: bool) -> str:
        """The end reason a user reads for a chunk's stop code."""
        if chunk.code == StopReason.FAILED:
            if paper:
                # No fold of the drive was found ahead (that ends as a turning point), and the adaptive march that
                # follows a failed equal step to its row (_follow_row) did not land there either.
                return (
                    "corrector failed at a fixed drive step (no turning point of the drive found before it, and the "
                    "path not followed to the step's value; an adaptive trace without steps / --steps shows where "
                    "it goes)"
                )
            text = f"corrector failed (step halved below {self.cfg.min_step:.1e} without converging)"
            floor = self._closure_floor(chunk)
            if floor is not None:
                # The misfit of a loop moved off its exact geometry grows along the path (to about four times the
                # imperfection on the built-ins): a hundred times the floor met here, to a power of ten.
                play = 10.0 ** np.ceil(np.log10(PLAY_MARGIN * floor))
                text += (
                    f"; the loop closes no better than {floor:.1e} here: rigid by a hair (an over-constrained "
                    f"loop written with rounded numbers?); accept play in the hinges, e.g. closure_tol / "
                    f"--closure-tol {play:.0e}"
                )
            return text
        if chunk.code == StopReason.NO_PROGRESS:
            return (
                f"no progress ({self.cfg.tol.stall_steps} steps advanced less than "
                f"{self.cfg.tol.stall_length:g} of the largest step)"
            )
        return StopReason(chunk.code).text

    def _closure_floor(self, chunk: Chunk) -> float | None:
        """Where an adaptive march failed: the closure residual at its last row, or the least one reached a short
        step (an eighth of the largest) ahead by Gauss-Newton until it stalls, when that is ten times the closure
        tolerance or more (the march went on only by accepting stalled residuals) and below :data:`PLAY_PROBE`:
        the loop is rigid by a hair there (a Bennett linkage written to ten digits stalled at 5.5e-11 and failed 83
        deg along its path). ``None`` otherwise."""
        c = chunk.count - 1
        tol = self.cfg.tol
        if c < 0 or tol.closure >= PLAY_PROBE:
            return None
        u, t = chunk.u[c], chunk.t[c]
        length = float(np.linalg.norm(t * self.weight))
        if not length > 0.0:
            return None
        step = (self.cfg.max_step / 8.0) / length
        _, ahead, _ = correct_on_plane(self.ws, u + step * t, t, tol.with_closure(PLAY_PROBE))
        floor = max(float(ahead), float(chunk.res[c]))
        return floor if 10.0 * max(tol.closure, tol.exact) < floor < PLAY_PROBE else None

    def _record(self, chunk: Chunk, branch_id: int, first: bool, n_steps: int) -> None:
        """Append a chunk's rows (all of them for the branch's first chunk, else without its start row)."""
        rows, count = self.rows, chunk.count
        s_base = rows.s[-1][-1] if (not first and rows.s) else np.zeros(2)
        begin = 0 if first else 1
        if count <= begin:  # a march that failed at its first step adds no row (no empty last block)
            return
        rows.u.append(chunk.u[begin:count])
        rows.sigma.append(chunk.sigma[begin:count])
        if chunk.rank is None:
            chunk.rank = numerical_ranks(chunk.sigma[:count], self.cfg.tol, self.ws.kernels.compiled)
        rows.rank.append(chunk.rank[begin:count])
        rows.res.append(chunk.res[begin:count])
        rows.tau.append(chunk.tau[begin:count])
        rows.s.append(s_base + chunk.s[begin:count])
        rows.branch.append(np.full(count - begin, branch_id, dtype=np.int64))
        rows.step.append(
            np.arange(n_steps + (0 if first else 1), n_steps + count - begin + (0 if first else 1))
        )
        if count > begin:
            self.max_misfit = max(self.max_misfit, float(chunk.res[begin:count].max()))

    # ---- what a chunk meets
    def _component_entry(self, chunk: Chunk, ranks: NDArray[np.int64]) -> int | None:
        """Index of the first of ``component_points`` consecutive points of mobility >= 2, if any (``ranks``: the
        rank of each row of the chunk)."""
        need = self.cfg.tol.component_points
        if chunk.count < need:
            return None
        mobility = len(chunk.u[0]) - ranks
        if not np.any(mobility >= 2):
            return None
        run = 0
        for k, mob in enumerate(mobility):
            run = run + 1 if mob >= 2 else 0
            if run >= need and k + 1 - need > 0:
                return k + 1 - need
        return None

    def _enter_component(self, chunk: Chunk, branch_id: int, step: int) -> tuple[int, str]:
        """Record where the branch meets a higher-dimensional component (once); returns its point and the end
        reason."""
        u = chunk.u[chunk.count - 1]
        known = self._match(u)
        if known is None:
            bif = classify_point(self.mech, self.ws, len(self.found), branch_id, step, u, 0.0, self.cfg)
            if bif.kind != "component":  # the mobility along the branch says so, whatever the samples found
                dim = self.mech.n_unknowns - numerical_rank(chunk.sigma[chunk.count - 1], self.cfg.tol)
                empty = np.zeros((0, len(u)))
                bif = replace(bif, kind="component", dimension=dim, tangents=empty, tangents_u=empty)
            self.found.append(bif)
            known = bif.id
        dim = self.found[known].dimension
        return known, f"entered a {dim}-dimensional component (mobility {dim}) at point {known}"

    def _scan_rank_minima(self, chunk: Chunk, branch_id: int, base: int, row_step: float = 0.0) -> None:
        """Rank drops where the test function keeps its sign: local minima of ``sigma_r / sigma_1``.

        A minimum is looked into where the ratio is below ``Tolerances.local_min`` at a row (the locator then
        keeps it where the ratio falls to ``Tolerances.loose``). ``row_step``: paper mode's equal drive step; rows
        further apart than ``max_step`` may straddle a rank drop at half a row or more from each (the ratio grows
        about linearly with the distance from it: Sarrus's folded configuration between rows 16 deg apart reads
        0.03 and 0.04, at link 30 and height 11 rows 4 deg apart read 0.043 and 0.041), so there every local
        minimum is looked into, where the ratio dips by more than :data:`MINIMUM_DIP` of its higher neighbour
        (not the round-off wobble of a flat ratio): a few locator calls per path, only for such coarse rows."""
        r_path, tol, count = self.cfg.r_path, self.cfg.tol, chunk.count
        if r_path < 1 or count < 3:
            return
        ratio = chunk.sigma[:count, r_path - 1] / chunk.sigma[:count, 0]
        tau = chunk.tau
        inner = ratio[1:-1]
        small = inner < tol.local_min
        if abs(row_step) * float(self.weight[self.cfg.drive]) > self.cfg.max_step:
            small |= inner < (1.0 - MINIMUM_DIP) * np.maximum(ratio[:-2], ratio[2:])
        minima = (inner <= ratio[:-2]) & (inner < ratio[2:]) & small
        for k in (minima.nonzero()[0] + 1).tolist():
            if tau[k - 1] * tau[k] < 0.0 or tau[k] * tau[k + 1] < 0.0:
                continue  # a sign change: located by the test function
            u_min, r_min = locate_minimum(
                self.ws, chunk.u[k - 1], chunk.t[k - 1], chunk.u[k + 1], chunk.t[k + 1], r_path, tol
            )
            if r_min <= tol.loose and self._match(u_min) is None:
                bif = classify_point(
                    self.mech, self.ws, len(self.found), branch_id, base + k, u_min, 0.0, self.cfg
                )
                self._add_point(bif, branch_id, chunk.t[k])
                self._onto_point(chunk, k, bif)

    def _scan_folds(
        self, chunk: Chunk, branch_id: int, base: int, at: int | None = None, first: bool = False
    ) -> None:
        """Locate every fold of the drive in the chunk: where the drive turns back.

        A fold between the chunk's rows ``k`` and ``k + 1`` is recorded at step ``base + k``, the branch's row
        before it; ``at``: the step every fold found is recorded at instead, for a probe whose rows are not the
        branch's (paper mode's :meth:`_follow_row`: the fold lies after the branch's last row, ``at``). ``first``:
        the chunk's row 0 is the branch's start, which is not a fold the branch meets when it sits on one (its
        drive component below :data:`FOLD_START`, of round-off's sign: a slider-crank started at a dead centre).

        A candidate is a step over which the tangent's drive component changes sign while moving by more than
        :data:`FOLD_MOVING` on at least one side; the located point is kept when the drive's value there is an
        extreme of the step (beyond both ends, by more than round-off), so a branch along which the drive is
        constant (its tangent component only noise) has no folds.
        """
        d = self.cfg.drive
        tw = chunk.t[: chunk.count] * self.weight  # the tangents in the step's metric (scale-free)
        td = tw[:, d] / np.linalg.norm(tw, axis=1)
        if first and abs(td[0]) < FOLD_START:
            td[0] = 0.0
        turned = (td[:-1] * td[1:] < 0.0).nonzero()[0]
        if len(turned) == 0:
            return
        moving = np.maximum(np.abs(td[:-1]), np.abs(td[1:])) > FOLD_MOVING
        joint = self.cfg.drive_joint if self.cfg.drive_joint >= 0 else self.first_joint[d]
        for k in turned[moving[turned]]:
            u_a, u_b = chunk.u[k], chunk.u[k + 1]
            u_f = locate_fold(self.ws, u_a, chunk.t[k], u_b, chunk.t[k + 1], d, self.cfg.tol, self.weight)
            beyond = np.sign(td[k]) * (u_f[d] - np.array([u_a[d], u_b[d]]))
            w = float(self.weight[d])  # round-off of the drive's value, in its own unit
            noise = 1e-13 * max(1.0, abs(float(u_f[d])) * w) / w
            if beyond.min() < -noise or beyond.max() <= noise:
                continue  # the drive does not turn back here
            angles = self.mech.angles_from_q(self.mech.q_from_u(u_f))
            step = base + int(k) if at is None else at
            self.folds.append(Fold(branch_id, step, float(angles[joint]), angles))

    def _on_sign_change(self, chunk: Chunk, basis_prev: Array, branch_id: int, step: int) -> int | None:
        """Locate every zero of the test function over the chunk's last row; returns the id of the point located
        when it was already known (an adaptive step's one sign change; a paper row's known points are noted as
        passed here, as it goes on through them).

        An adaptive step is the bracket. A paper row's sign is compared part by part in the march, which hands
        back the bracket of each part over which it changed (``chunk.crossings``): two crossings inside one row
        (a parallelogram's at 180 and 360 deg in one equal step from 30 to 370 deg) leave the row's sign as it
        was, and are each located and reported."""
        c = chunk.count
        if chunk.crossings is None:
            basis_a = self._basis_before(chunk.u[c - 2], chunk.t[c - 2], basis_prev)
            bracket = (chunk.u[c - 2], chunk.t[c - 2], basis_a, chunk.u[c - 1], chunk.t[c - 1])
            return self._locate_crossing(chunk, bracket, branch_id, step)
        cross_u, cross_t, cross_basis, cross_n = chunk.crossings
        for k in range(min(int(cross_n[0]), MAX_CROSSINGS)):
            bracket = (cross_u[k, 0], cross_t[k, 0], cross_basis[k], cross_u[k, 1], cross_t[k, 1])
            known = self._locate_crossing(chunk, bracket, branch_id, step)
            if known is not None:  # through a known point and on: the arcs on both sides are traced
                self._arrived(known, cross_u[k, 1] - cross_u[k, 0])
                self._arrived(known, cross_u[k, 0] - cross_u[k, 1])
        return None

    def _locate_crossing(
        self, chunk: Chunk, bracket: tuple[Array, Array, Array, Array, Array], branch_id: int, step: int
    ) -> int | None:
        """Locate the zero of the test function in ``bracket = (u_a, t_a, basis_a, u_b, t_b)``, a step (or a
        paper row's part) of the chunk's last row, ``basis_a`` the oriented range basis at ``u_a``; classify and
        keep a new point (its branches queued), and put the chunk's last two rows onto it when they are on it.
        Returns the id if already known."""
        cfg, c = self.cfg, chunk.count
        u_a, t_a, basis_a, u_b, t_b = bracket
        passed = self._known_on_step(u_a, u_b)
        if passed is not None:
            return passed
        u_star, width = locate(
            self.ws, u_a, t_a, basis_a, u_b, t_b, cfg.r_path, cfg.tol, cfg.n_sigma, self.weight,
        )  # fmt: skip
        known = self._match(u_star)
        if known is None:
            bif = classify_point(self.mech, self.ws, len(self.found), branch_id, step, u_star, width, cfg)
            if bif.kind != "component" and bif.rank >= cfg.r_path:
                # No rank drop where the test function vanishes: next to a bifurcation opened by an imperfection
                # (an over-constrained loop written with rounded numbers) the path turns sharply and the test
                # function changes sign there, while the rank drops at the nearest approach, within the step.
                u_min, r_min = locate_minimum(self.ws, u_a, t_a, u_b, t_b, cfg.r_path, cfg.tol)
                if r_min <= cfg.tol.loose and self._match(u_min) is None:
                    bif = classify_point(
                        self.mech, self.ws, len(self.found), branch_id, step, u_min, 0.0, cfg
                    )
            if bif.kind != "component" and bif.rank >= cfg.r_path:
                self.spurious += (
                    1  # the test function changed sign without a rank drop: not a point to report
                )
            else:
                self._add_point(bif, branch_id, t_a)
                for row in (c - 2, c - 1):
                    self._onto_point(chunk, row, bif)
        return known

    def _known_on_step(self, u_a: Array, u_b: Array) -> int | None:
        """A located point the step from ``u_a`` to ``u_b`` passes through (again), if any."""
        periodic = self.cfg.periodic

        def dist(x: Array, y: Array) -> float:
            diff = x - y
            diff[periodic] = wrap(diff[periodic])
            return float(np.linalg.norm(diff))

        length = dist(u_a, u_b)
        for b in self.found:
            if dist(u_a, b.u) + dist(b.u, u_b) <= length * (1.0 + 1e-3) + self.cfg.tol.locate:
                return b.id
        return None

    def _add_point(self, bif: Bifurcation, branch_id: int, incoming: Array) -> None:
        """Keep a classified point and queue its new branches (both directions) when switching branches.

        Of a branch's two directions the one along which the drive increases is queued (and so traced) first, or,
        where the drive stays put, the one along which the first unknown that moves increases: a branch tangent's
        sign is whatever the SVD of the point's Jacobian gave it, which round-off can flip."""
        self.found.append(bif)
        if not self.switch_branches or bif.kind != "bifurcation":
            return
        for tb in bif.tangents_u:
            if abs(tb @ incoming) < self.cfg.tol.same_branch:
                first = leading_sign(tb, self.cfg.drive)
                for direction in (first, -first):
                    self.queue.append(QueuedBranch(branch_id, bif.id, bif.u, direction * tb, direction))

    def _end_on_known(self, chunk: Chunk, known: int) -> None:
        """End the branch exactly on a known point (its last row overshot it by part of a step)."""
        before = chunk.u[chunk.count - 2]
        diff = self.found[known].u - before
        diff[self.cfg.periodic] = wrap(diff[self.cfg.periodic])
        point = before + diff  # the same point, in this branch's continuous angles
        r_known, _, j_known = self.ws.evaluate(point)
        rows = self.rows
        rows.u[-1][-1] = point
        rows.sigma[-1][-1] = np.linalg.svd(j_known, compute_uv=False)[: self.cfg.n_sigma]
        rows.rank[-1][-1] = numerical_rank(rows.sigma[-1][-1], self.cfg.tol)
        rows.res[-1][-1] = r_known
        rows.tau[-1][-1] = 0.0
        self._arrived(known, diff)

    def _arrived(self, point: int, direction: Array) -> None:
        """Note that a traced branch came into located point ``point`` moving along ``direction`` (unknowns)."""
        norm = float(np.linalg.norm(direction))
        if norm > 0.0:
            self.arrivals.append((point, direction / norm))

    def _passed(self, point: int, chunk: Chunk) -> None:
        """Note that the branch of ``chunk`` went through located point ``point`` along its last step."""
        step = chunk.u[chunk.count - 1] - chunk.u[chunk.count - 2]
        step[self.cfg.periodic] = wrap(step[self.cfg.periodic])
        self._arrived(point, step)
        self._arrived(point, -step)

    def _traced_already(self, job: QueuedBranch) -> bool:
        """Whether leaving ``job``'s point along its tangent runs back along an arc a traced branch arrived by: the
        same arc the other way round (a closed mode through the point, or the arc between two located points)."""
        tangent = job.tangent / np.linalg.norm(job.tangent)
        return any(
            point == job.bifurcation and float(direction @ tangent) < -self.cfg.tol.same_branch
            for point, direction in self.arrivals
        )

    def _basis_before(self, u: Array, t: Array, basis_prev: Array) -> Array:
        """The oriented range basis at point ``u`` (as the march kept it), recomputed for the locator."""
        _, _, jac = self.ws.evaluate(u)
        basis = basis_prev.copy()
        self.ws.kernels.tangent_and_test(
            jac, t.copy(), basis, self.cfg.r_path, np.empty_like(t), np.empty(min(jac.shape)), self.weight
        )
        return basis

    def _match(self, u: Array) -> int | None:
        """Id of an already located point at ``u`` (angles compared modulo a full turn), if any."""
        tol = self.cfg.tol.same_point * max(1.0, float(np.linalg.norm(u)))
        for b in self.found:
            diff = b.u - u
            diff[self.cfg.periodic] = wrap(diff[self.cfg.periodic])
            if np.linalg.norm(diff) < tol:
                return b.id
        return None

    # ---- the queued branches
    def follow_queue(self) -> None:
        """Trace every queued branch (breadth first) while the step budget lasts."""
        while self.queue and self.budget > 0:
            if (
                self.stop_requested()
            ):  # the rest of the queue is not traced: the trace says it was interrupted
                return
            job = self.queue.pop(0)
            if self._traced_already(job):
                self.retraced += 1
                continue
            bid = len(self.branches)
            left = self.leave_point(bid, job.u, job.tangent, job.bifurcation)
            if left is None:
                end = self.end(StopReason.NOT_LEFT, StopReason.NOT_LEFT.text, job.u, None, job.bifurcation)
                self.branches.append(Branch.ended(bid, job.parent, job.bifurcation, job.direction, 0, end))
                continue
            nb, end = left
            self.branches.append(Branch.ended(bid, job.parent, job.bifurcation, job.direction, nb, end))

    def start_at_point(self, point: Bifurcation, incoming: Array) -> None:
        """Keep the start, a located singular point (a crossing of branches), as point 0; with branch switching,
        its branch tangents other than ``incoming`` (the one branch 0 leaves along) are queued."""
        self._add_point(point, 0, incoming)

    def leave_point(self, bid: int, u: Array, tangent: Array, point: int) -> tuple[int, End] | None:
        """March branch ``bid`` from the located point ``u`` (id ``point``) along the branch tangent ``tangent``
        (adaptive steps, stopping at known points): the point is its first row, then one step of a quarter of
        ``max_step`` corrected on the plane normal to the tangent, then the march. Returns (steps, end), or
        ``None`` when that first step does not converge (the branch could not be left)."""
        cfg = self.cfg
        h = cfg.max_step / 4.0
        u1, _r, ok = correct_on_plane(self.ws, u + h * tangent, tangent, cfg.tol)
        if not ok:
            return None
        _, _, jac1 = self.ws.evaluate(u1)
        U1, _, Vt1 = np.linalg.svd(jac1)
        t1 = Vt1[-1] if Vt1[-1] @ tangent > 0 else -Vt1[-1]
        # Record the point itself as the branch's first point, then march on.
        r_star, _, jst = self.ws.evaluate(u)
        sigma_star = np.asarray(np.linalg.svd(jst, compute_uv=False)[: cfg.n_sigma], dtype=float)
        self.rows.add_point(u, sigma_star, r_star, bid, numerical_rank(sigma_star, cfg.tol))
        s_off = self.chords(u, u1)
        start_len = len(self.rows.u)
        basis = np.ascontiguousarray(U1[:, : cfg.r_path])
        opened_at = (u, Home(sigma_star, float(r_star), 0.0))
        nb, end = self.run_branch(
            bid, u1, t1, basis, paper=False, h0=h, stop_at_known=True, step_offset=1, opened_at=opened_at
        )
        for i in range(start_len, len(self.rows.u)):
            self.rows.s[i] = self.rows.s[i] + s_off
            self.rows.step[i] = self.rows.step[i] + 1
        if end.kind == StopReason.CLOSED:  # back round to where it left its point: a closed mode through it
            block = self.rows.u[-1]
            step = block[-1] - (block[-2] if len(block) > 1 else self.rows.u[-2][-1])
            step[self.cfg.periodic] = wrap(step[self.cfg.periodic])
            self._arrived(point, step)
        return nb + 1, end
