"""Mechanization (Sec. 7): add binary links to the synthesised chain until it has the DOF asked for, verified.

:func:`mechanize` plans the build-up order and the ranked candidates (:mod:`linkwork.mechanization.search`),
assembles a design from the best candidates, verifies it by tracing (:mod:`linkwork.mechanization.verify`) and,
when a design fails, replaces the link blamed for the defect by its next candidate, until one passes or the
attempts run out.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, field, replace

import numpy as np

from linkwork.errors import SpecError
from linkwork.interrupts import requested, stop_text, whole
from linkwork.mechanization.assemble import BinaryLink, Design
from linkwork.mechanization.chain import ShapeChain, build_chain
from linkwork.mechanization.inside import verified
from linkwork.mechanization.options import (
    ACTUATORS,
    ANCHORS,
    BINARY_LINKS,
    MechanizeOptions,
    ProgressCallback,
    options_from_values,
)
from linkwork.mechanization.pivot_fit import fit_pivots, fits
from linkwork.mechanization.quality import Quality, quality
from linkwork.mechanization.recut import Recut, monotone_recut
from linkwork.mechanization.search import (
    MechanizationError,
    NoPlan,
    Plan,
    Step,
    plan,
    prismatic_actuator,
    roots,
)
from linkwork.mechanization.verify import Verification
from linkwork.messages import show
from linkwork.synthesis.result import SynthesisResult


@dataclass(frozen=True)
class RankedDesign:
    """A design that passed verification, and its quality factor (:mod:`linkwork.mechanization.quality`)."""

    design: Design
    verification: Verification
    quality: Quality


@dataclass(frozen=True)
class Mechanization:
    """A verified mechanized design and how it was found.

    Attributes
    ----------
    design
        The chain, its binary links and drive: the passing design of highest quality factor.
    verification
        DOF, the state on every profile, the traced paths.
    attempts
        Designs traced.
    rejected
        One line per rejected design: why.
    seconds
        Wall time.
    ranked
        Up to ``options.designs`` (5) passing designs, best quality factor first (``ranked[0]`` is ``design``).
    options
        The options the search ran with (the limits it kept are reported from them).
    recut
        When the mechanism follows the chain re-cut with monotonic C-segment piece counts
        (:mod:`linkwork.mechanization.recut`): the re-cut, with the synthesised segment matrix and joined errors.
    stopped
        Why the search stopped before its end (``"interrupted (SIGTERM)"``: a signal held by the command line,
        :func:`linkwork.interrupts.held_signals`), so that ``design`` is the best of the designs that passed so
        far; ``None`` when the search ran to its end.
    """

    design: Design
    verification: Verification
    attempts: int
    rejected: tuple[str, ...]
    seconds: float
    ranked: tuple[RankedDesign, ...] = ()
    options: MechanizeOptions | None = None
    recut: Recut | None = None
    stopped: str | None = None

    @property
    def complete(self) -> bool:
        """Whether the search ran to its end (not stopped by a signal)."""
        return self.stopped is None


@dataclass
class _Search:
    """The state of one mechanization search: what passed, what came closest, how much was traced."""

    options: MechanizeOptions
    started: float
    progress: ProgressCallback | None
    total: int
    attempts: int = 0
    passed: list[RankedDesign] = field(default_factory=list)
    rejected: list[str] = field(default_factory=list)
    closest: list[tuple[int, str]] = field(default_factory=list)

    def out_of_time(self) -> bool:
        """The search's time limit has passed."""
        return time.perf_counter() - self.started > self.options.time_limit

    def done(self) -> bool:
        """Enough designs passed, the time is up, or a signal asks the search to stop (it keeps what passed)."""
        return self.out_of_time() or len(self.passed) >= self.options.designs or bool(requested())

    def unusable(self, line: str, *, near_inside: bool = False) -> None:
        """Record a plan or design that could not be traced (among the closest while nothing was traced; one
        that says how a link leaves the shape, ``near_inside``, ahead of one that does not)."""
        self.rejected.append(line)
        self._closer(-1 if near_inside else -2, line)

    def _closer(self, reached: int, line: str) -> None:
        """Keep the :data:`CLOSEST` designs that reached the most profiles (the first found first on a tie)."""
        self.closest.append((reached, line))
        self.closest.sort(key=lambda c: -c[0])  # stable: earlier designs stay ahead on a tie
        del self.closest[CLOSEST:]

    def traced(self, label: str, design: Design, check: Verification) -> None:
        """Record a verified design (passed or rejected) and report progress."""
        self.attempts += 1
        if check.passed:
            final = _with_transmissions(design, check)
            self.passed.append(RankedDesign(final, check, quality(final, check)))
        else:
            self.rejected.append(f"{label}: {check.reason}")
            reached = len(check.states)
            links = ", ".join(f"{link.name} {link.anchor}-{link.body}" for link in design.links)
            self._closer(
                reached,
                f"{label} (links {links}; drive {design.drive}) reached profile {reached} of {design.chain.count}, "
                f"then: {check.reason}",
            )
        if self.progress is not None:
            self.progress(self.attempts, self.total)


def _design(
    chain: ShapeChain, pl: Plan, root_pair: int, choice: list[int], options: MechanizeOptions, name: str
) -> Design:
    links: list[BinaryLink] = []
    count = 0

    def add(link: BinaryLink) -> None:
        nonlocal count
        count += 1
        links.append(replace(link, name=f"D{count}"))

    if pl.pinned_root is None:
        a, b, _ = pl.root_pairs[root_pair]
        add(replace(a.link, via="D2"))
        add(replace(b.link, via="D1"))
    for step, k in zip(pl.steps, choice, strict=True):
        first = step.candidates[k].link
        add(first)
        if step.links == 2:
            second = next(
                (
                    c.link
                    for c in step.candidates[k + 1 :]
                    if _independent(first, c.link, chain.size, options)
                    # not both from the body the pair hangs from: with the pair's two joints that makes the
                    # pair rigid on it, and the profiles' motion of the pair would be frozen
                    and not (first.anchor == c.link.anchor == step.hangs_from)
                ),
                step.candidates[(k + 1) % len(step.candidates)].link,
            )
            add(second)
    if options.actuator == "prismatic":
        links.append(prismatic_actuator(chain, pl.root, options))
    if options.drive is not None:
        drive = options.drive
    elif options.actuator == "prismatic":
        drive = "A1s"
    elif any(link.kind == "PR" for link in links):
        drive = next(
            f"{link.name}s" for link in links if link.kind == "PR"
        )  # a slider drives (paper, Fig. 14)
    elif pl.pinned_root is not None:
        drive = pl.pinned_root
    else:
        drive = links[0].joint_names()[0]  # the root's crank
    notes = (
        f"root body {pl.root}",
        f"bodies closed by two chain joints: {', '.join(pl.paired) or 'none'}",
        f"bodies left free (extra inputs): {', '.join(pl.free) or 'none'}",
        f"bodies the closing body frees from a link: {', '.join(pl.closing) or 'none'}",
    )
    return Design(chain, tuple(links), drive, options.dof, name, notes)


def _independent(first: BinaryLink, second: BinaryLink, size: float, options: MechanizeOptions) -> bool:
    """Two links that together can hold a body: apart, and two sliders not on parallel guides."""
    if first.kind == "PR" and second.kind == "PR" and first.anchor == second.anchor:
        assert first.direction is not None and second.direction is not None
        sine = abs(float(first.direction[0] * second.direction[1] - first.direction[1] * second.direction[0]))
        if sine < math.sin(options.min_transmission):
            return False
    return first.anchor != second.anchor or float(np.linalg.norm(second.circle - first.circle)) > 0.1 * size


def mechanize(
    result: SynthesisResult | ShapeChain,
    options: MechanizeOptions | None = None,
    *,
    name: str | None = None,
    progress: ProgressCallback | None = None,
) -> Mechanization:
    """Mechanize a synthesised chain to ``options.dof`` degrees of freedom (1 by default), verified.

    Parameters
    ----------
    result
        A synthesis result (its compound chain is used when joints were merged), or a chain already built.
    options
        Designer choices: DOF, ground region, link offsets, anchors, drive, actuator type (default: the
        problem file's mechanization keys).
    name
        The mechanism's name (default: from the problem file).
    progress
        Called as ``progress(done, total)`` (:class:`linkwork.progress.Progress`) after every design traced (``total``: the most the search
        will trace).

    A SIGINT or SIGTERM held by the command line (:func:`linkwork.interrupts.held_signals`) stops the search
    after the design being traced: the best design passed so far is returned, its ``stopped`` saying why.

    Raises
    ------
    MechanizationError
        When no design passes (or none had passed when a signal stopped the search): the design that came closest
        (the most profiles reached) and what it violated, and how many designs were tried.
    """
    options = _options(result, options)
    chain, label = _chain(result, name)
    check_names(chain, options)
    started = time.perf_counter()
    recut = monotone_recut(result) if isinstance(result, SynthesisResult) else None
    if recut is None:
        return _search_chain(chain, options, label, progress)
    # the same design vector cut with every C-segment's piece count moving one way (recut.py), which a one-DOF
    # mechanism follows: first when there are more than five profiles (least-squares links: a zigzag of an arc
    # slide costs shape everywhere) and it joins the profiles about as well, else after the synthesised cut
    # (with exact links the mechanism sits on the chain as synthesised); the first gets half the time, the
    # second what is left
    cuts: list[tuple[ShapeChain, Recut | None]] = [(build_chain(recut.result), recut), (chain, None)]
    if chain.count <= 5 or not _joins_as_well(recut, chain):
        cuts.reverse()
    failures = []
    for k, (cut, used) in enumerate(cuts):
        left = options.time_limit - (time.perf_counter() - started)
        limit = 0.5 * options.time_limit if k == 0 else max(0.0, left)
        try:
            found = _search_chain(cut, replace(options, time_limit=limit), label, progress)
        except MechanizationError as exc:
            if requested():  # stopped by a signal before anything passed: the other cut is not tried
                raise
            what = f"the re-cut chain ({recut.describe()})" if used else "the chain as synthesised"
            failures.append((what, str(exc).removeprefix("mechanize: ")))
            continue
        return replace(found, recut=used, seconds=time.perf_counter() - started)
    (first, why), (second, why_second) = failures
    raise MechanizationError(f"mechanize: {why} (on {first}); and on {second}: {why_second}")


#: The re-cut chain is mechanized first when its joined ``E_max`` is at most this many times the synthesised
#: chain's plus a thousandth of the size (on the NACA camber lines it is the same; a re-cut joining worse is
#: tried after the synthesised cut).
RECUT_ALLOWANCE = 1.1


def _joins_as_well(recut: Recut, chain: ShapeChain) -> bool:
    """The re-cut chain joins the profiles about as well as the synthesised one."""
    after = max(float(np.max(prof.errors)) for prof in recut.result.joined)
    return after <= RECUT_ALLOWANCE * float(np.max(recut.joined_before)) + 1e-3 * chain.size


def _search_chain(
    chain: ShapeChain, options: MechanizeOptions, label: str, progress: ProgressCallback | None
) -> Mechanization:
    """The search over roots and anchor choices on one chain (see :func:`mechanize`)."""
    # "any" first: every design that passed in the examples and the NACA sets joins two bodies by a dyad, and
    # the ground-only plans of a root, tried first, doubled the search (the nine-body wing: 37 s of CPU, now 14 s)
    modes = ("any", "ground") if options.anchors == "auto" else (options.anchors,)
    order = roots(chain, options)
    most = options.attempts * (1 + REDRIVES) * len(order) * len(modes)
    state = _Search(options, time.perf_counter(), progress, most)
    for root in order:
        for mode in modes:
            if state.done():
                break
            opts = replace(options, anchors=mode)
            try:
                pl = plan(chain, root, opts)
            except MechanizationError as exc:
                if requested():  # a signal stopped the planning: no verdict on this root
                    break
                state.unusable(
                    f"root {root}, anchors {mode}: {exc}",
                    near_inside=isinstance(exc, NoPlan) and exc.near_inside,
                )
                continue
            _search(chain, pl, opts, label, state)
        if state.passed:  # the designs of one root are compared; other roots only when none passed
            break
    return _outcome(state)


def _options(result: SynthesisResult | ShapeChain, options: MechanizeOptions | None) -> MechanizeOptions:
    """The options asked for (default: the problem file's mechanization keys), checked."""
    if options is None:
        problem = getattr(result, "problem", None)
        options = (
            options_from_values(problem.mechanize_options) if problem is not None else MechanizeOptions()
        )
    _check(options)
    return options


def _chain(result: SynthesisResult | ShapeChain, name: str | None) -> tuple[ShapeChain, str]:
    """The chain to mechanize and the mechanism's name.

    Raises
    ------
    MechanizationError
        With fewer than three profiles.
    """
    if isinstance(result, ShapeChain):
        chain = result
        label = name or "mechanized chain"
    else:
        chain = build_chain(result)
        source = result.problem.source
        label = name or (f"{source.parent.name} mechanized" if source is not None else "mechanized chain")
    if chain.count < 3:
        raise MechanizationError(
            f"mechanize: needs at least three profiles, got {chain.count}: rigid-body guidance places each pivot "
            "through three or more positions of a body (Sec. 7)"
        )
    return chain, label


def _outcome(state: _Search) -> Mechanization:
    """The best passing design with the others ranked.

    Raises
    ------
    MechanizationError
        When none passed: the closest design and what it violated.
    """
    seconds = time.perf_counter() - state.started
    if state.passed:
        # ties (the same weakest link) keep the order found: rounding keeps that order stable to the last bits
        ranked = tuple(sorted(state.passed, key=lambda r: -round(r.quality.factor, 9)))
        best = ranked[0]
        return Mechanization(
            best.design,
            best.verification,
            state.attempts,
            tuple(state.rejected),
            seconds,
            ranked,
            state.options,
            stopped=stop_text(requested()) if requested() else None,
        )
    lines = [line.removeprefix("mechanize: ") for _, line in state.closest]
    closest = " | ".join(f"({k}) {line}" for k, line in enumerate(lines, start=1)) if lines else "no design"
    timed_out = " (time limit reached)" if state.out_of_time() else ""
    if requested():
        timed_out = f" ({stop_text(requested())})"
    dof = state.options.dof
    raise MechanizationError(
        f"mechanize: no design passes after {state.attempts} traced{timed_out}"
        + (f" (DOF {dof} asked for)" if dof != 1 else "")
        + f"; closest: {closest}"
    )


#: The closest failed designs named when none passes.
CLOSEST = 3

#: A design with an order defect (its drive turns back) is traced again driven by at most this many other joints
#: (those moving one way through the profiles, the most evenly first), unless the designer chose the drive.
REDRIVES = 3

#: Designs of one plan (root and anchors) whose pivots are fitted jointly when they fail (each fit costs about as
#: much as tracing a few designs; the next designs of a plan differ from the first by one link).
FITS = 2

#: Joints of the added links a design may have: an RR dyad's ``D<k>a`` / ``D<k>m``, a slider's ``D<k>s``, the
#: linear actuator's ``A1a`` / ``A1s`` / ``A1m``.
LINK_JOINT = re.compile(r"^(D[1-9][0-9]*[ams]|A1[ams])$")


#: The names a chain built by :mod:`linkwork.mechanization.chain` gives its joints (``J<k>`` revolute, ``S<k>``
#: slides) and bodies (``ground``, ``s<k>``, a split segment's ``s<k>a`` / ``s<k>b``).
CHAIN_JOINT = re.compile(r"^[JS][1-9][0-9]*$")
CHAIN_BODY = re.compile(r"^(ground|s[1-9][0-9]*[ab]?)$")


def check_name_forms(options: MechanizeOptions) -> None:
    """Refuse a ``drive`` or ``root`` that no chain can have, before anything is synthesised or searched: a drive
    is a chain joint (``J<k>``, ``S<k>``) or a joint of an added link; a root a body (``ground``, ``s<k>``,
    ``s<k>a``, ``s<k>b``). Whether the chain at hand has it is :func:`check_names`'s.

    Raises
    ------
    SpecError
        Naming the option and the forms expected (bad input, exit code 2).
    """
    if options.root is not None and not CHAIN_BODY.match(options.root):
        raise SpecError(
            f"unknown body {show(options.root)}; expected a body of the chain: ground, s<k>, s<k>a or s<k>b",
            key="root",
        )
    if options.drive is not None and not (
        CHAIN_JOINT.match(options.drive) or LINK_JOINT.match(options.drive)
    ):
        raise SpecError(
            f"unknown joint {show(options.drive)}; expected a chain joint (J<k>, S<k>) or a joint of an added link: "
            "D<k>a, D<k>m, D<k>s or A1s",
            key="drive",
        )


def check_names(chain: ShapeChain, options: MechanizeOptions) -> None:
    """Refuse a ``drive`` or ``root`` that no design of this chain can have, naming the choices.

    Raises
    ------
    SpecError
        ``drive`` (neither a chain joint nor a link joint ``D<k>a``, ``D<k>m``, ``D<k>s``, ``A1s``) or ``root``
        (not a body of the chain): bad input, exit code 2.
    """
    bodies = [b.name for b in chain.bodies]
    if options.root is not None and options.root not in bodies:
        raise SpecError(f"unknown body {options.root!r}; expected one of {', '.join(bodies)}", key="root")
    joints = [j.name for j in chain.joints]
    if options.drive is not None and options.drive not in joints + link_joints(chain, options):
        count = max(0, chain.mobility() - options.dof)
        kinds = {"revolute": "a, m", "prismatic": "s, m", "both": "a, s, m"}[options.binary_links]
        actuator = "; the linear actuator A1a, A1s, A1m" if options.actuator == "prismatic" else ""
        raise SpecError(
            f"unknown joint {options.drive!r}; expected a chain joint ({', '.join(joints) or 'none'}) or a joint "
            f"of the {count} added links D1 ... D{count} (suffix {kinds}: a an RR link's fixed pivot, m its "
            f"moving pivot, s a slider){actuator}",
            key="drive",
        )


def link_joints(chain: ShapeChain, options: MechanizeOptions) -> list[str]:
    """Every joint name an added link of a design of ``chain`` can have under ``options``: the links ``D1`` ...
    ``D<n>`` (``n`` the chain's mobility less the DOF asked for: each binary link takes one) with the suffixes of
    the link types allowed, and the linear actuator's ``A1a``, ``A1s``, ``A1m`` when it is asked for."""
    count = max(0, chain.mobility() - options.dof)
    suffixes = {"revolute": "am", "prismatic": "sm", "both": "asm"}[options.binary_links]
    names = [f"D{k}{x}" for k in range(1, count + 1) for x in suffixes]
    if options.actuator == "prismatic":
        names += ["A1a", "A1s", "A1m"]
    return names


def _check(options: MechanizeOptions) -> None:
    """Reject options no search can use (the problem reader and the flags check them too): bad input, exit 2.

    Raises
    ------
    SpecError
        Naming the option and what was expected.
    """
    if options.dof < 1:
        raise SpecError(f"{options.dof}: expected a whole number >= 1", key="dof")
    for key, choices in (("actuator", ACTUATORS), ("binary_links", BINARY_LINKS), ("anchors", ANCHORS)):
        value = getattr(options, key)
        if value not in choices:
            quoted = [f"'{c}'" for c in choices]
            raise SpecError(f"{value!r}: expected {', '.join(quoted[:-1])} or {quoted[-1]}", key=key)


def _with_transmissions(design: Design, check: Verification) -> Design:
    """The design with each RR link's smallest transmission angle over the profiles as traced."""
    from linkwork.mechanization.verify import link_transmissions, loaded_mechanism

    mech = loaded_mechanism(design)
    worst: dict[str, float] = {}
    for state in check.states:
        for name, s in link_transmissions(design, mech, state.values).items():
            worst[name] = min(worst.get(name, 1.0), s)
    links = tuple(
        replace(link, transmission=float(np.arcsin(min(1.0, worst[link.name]))))
        if link.name in worst
        else link
        for link in design.links
    )
    return replace(design, links=links)


def _search(chain: ShapeChain, pl: Plan, options: MechanizeOptions, label: str, state: _Search) -> None:
    """Trace designs of one plan, replacing the link blamed for each defect; after a pass, vary the links to
    find further passing designs to rank, until ``options.designs`` passed or the attempts or the time run out."""
    choice = [0] * len(pl.steps)
    root_pair = 0
    index: dict[str, int] = {}
    count = 0 if pl.pinned_root else 2
    for i, step in enumerate(pl.steps):
        for _ in range(step.links):
            count += 1
            index[f"D{count}"] = i
    fits_left = FITS
    failed: dict[int, list[int]] = {}  # step -> the candidates that failed when blamed
    blamed: tuple[int, str | None] | None = None  # the step blamed last, and for what
    for attempt in range(1, options.attempts + 1):
        if state.done():
            return
        design = _design(chain, pl, root_pair, choice, options, label)
        if options.drive is not None and options.drive not in design.joint_names():
            # a link's joint names depend on the design: this one has no such joint, another may
            state.unusable(
                f"root {pl.root}, anchors {options.anchors}, design {attempt}: no joint {options.drive!r} "
                f"(joints are {', '.join(design.joint_names())})"
            )
            return
        label_k = f"root {pl.root}, anchors {options.anchors}, design {attempt}"
        check = _verified(design, options)  # with the inside check on the traced poses
        state.traced(label_k, design, check)
        if check.defect == "order" and options.drive is None:
            design, check = _redrive(design, check, label_k, state)
        if fits_left and _fittable(design, check):
            fits_left -= 1
            design, check = _fitted(design, check, label_k, options, state)
        if check.defect == "dof":
            return
        # after a pass, replace the weakest link (smallest transmission angle) to look for a better design
        culprit = _weakest(state.passed[-1].design) if check.passed else check.culprit
        if culprit in index and choice[index[culprit]] + 1 < len(pl.steps[index[culprit]].candidates) - 1:
            i = index[culprit]
            following = choice[i] + 1
            if not check.passed:
                failed.setdefault(i, []).append(choice[i])
                if blamed == (i, check.defect):
                    # blamed again for the same defect: its next candidates are likely its near twins, which
                    # share the defect (a dead centre of the same group between the same profiles)
                    following = _apart(pl.steps[i], failed[i], following, chain.size)
                blamed = (i, check.defect)
            choice[i] = following
            continue
        if pl.pinned_root is None and root_pair + 1 < len(pl.root_pairs):
            root_pair += 1
            continue
        movable = [i for i, s in enumerate(pl.steps) if choice[i] + 1 < len(s.candidates) - 1]
        if not movable:
            return
        choice[movable[attempt % len(movable)]] += 1


#: After a step is blamed twice running for the same defect, its next candidate is one whose pivots are not both
#: within this fraction of the size of a candidate of that step that failed.
APART = 0.2


def _apart(step: Step, failed: list[int], start: int, size: float) -> int:
    """The first candidate of ``step`` from ``start`` (leaving the last, as the search does) whose anchor and
    moving pivots are not both within :data:`APART` times ``size`` of a ``failed`` candidate's; ``start`` when
    every one is."""
    links = [c.link for c in step.candidates]
    for k in range(start, len(links) - 1):
        near = any(
            float(np.linalg.norm(links[k].centre - links[f].centre)) < APART * size
            and float(np.linalg.norm(links[k].circle - links[f].circle)) < APART * size
            for f in failed
        )
        if not near:
            return k
    return start


def redrives(design: Design) -> list[str]:
    """Other joints that could drive ``design``: those whose values move one way through the profiles, the
    most evenly moving first (the smallest step between profiles over the largest), at most :data:`REDRIVES`."""
    ideal = design.expected_values()
    ranked: list[tuple[float, str]] = []
    for k, name in enumerate(design.joint_names()):
        steps = np.diff(ideal[:, k])
        largest = float(np.max(np.abs(steps)))
        if name == design.drive or largest <= 1e-9 or not (np.all(steps > 0) or np.all(steps < 0)):
            continue
        ranked.append((float(np.min(np.abs(steps))) / largest, name))
    ranked.sort(key=lambda r: -r[0])
    return [name for _, name in ranked[:REDRIVES]]


def _redrive(design: Design, check: Verification, label: str, state: _Search) -> tuple[Design, Verification]:
    """A design whose drive turns back (a dead centre of that joint) may pass driven from another joint: the
    mechanism is the same, only the joint that moves it one way through the profiles changes. The first that
    passes is kept; else the original verdict stands."""
    for other in redrives(design):
        if state.done():
            break
        again = replace(design, drive=other)
        verdict = _verified(again, state.options)
        state.traced(f"{label} re-driven from {other}", again, verdict)
        if verdict.passed:
            return again, verdict
    return design, check


def _verified(design: Design, options: MechanizeOptions) -> Verification:
    """:func:`~linkwork.mechanization.inside.verified`, run whole: a signal held meanwhile does not cut its traces
    short (a verdict on part of the motion would be no verdict); the search stops after it."""
    with whole():
        return verified(design, options)


def _fittable(design: Design, check: Verification) -> bool:
    """A design of least-squares links (more than five profiles) that failed on its shape or on its path (a
    defect the fitted pivots may not have) is worth fitting jointly (:mod:`pivot_fit`)."""
    inexact = any(
        link.kind == "RR" and link.structural_error > 1e-9 * design.chain.size for link in design.links
    )
    return (
        design.chain.count > 5
        and inexact
        and design.fitted is None
        and check.defect in ("circuit", "branch", "order")
    )


def _fitted(
    design: Design, check: Verification, label: str, options: MechanizeOptions, state: _Search
) -> tuple[Design, Verification]:
    """The design with every RR link's pivots fitted jointly to the profiles (the mechanism's own shape error
    minimised, :func:`linkwork.mechanization.pivot_fit.fit_pivots`), verified by tracing like any design. Kept
    when it passes; else the original verdict stands."""
    if state.done():
        return design, check
    chain = design.chain
    region = options.region_of(chain.targets, chain.size)
    longest = options.link_limit(chain.size)
    fitted = fit_pivots(
        design, options.structural_limit(chain.size), options.min_transmission, longest, region
    )
    broken = fits(fitted, longest, region)
    if broken is not None:
        state.rejected.append(f"{label} with its pivots fitted jointly: {broken}")
        return design, check
    verdict = _verified(fitted, options)
    state.traced(f"{label} with its pivots fitted jointly", fitted, verdict)
    return (fitted, verdict) if verdict.passed else (design, check)


def _weakest(design: Design) -> str | None:
    """The binary link with the smallest transmission angle."""
    links = [link for link in design.links if link.kind in ("RR", "PR")]
    return min(links, key=lambda link: link.transmission).name if links else None


__all__ = ["Mechanization", "MechanizationError", "MechanizeOptions", "RankedDesign", "mechanize"]
