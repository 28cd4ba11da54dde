"""Mechanization (Sec. 7): add binary links to the synthesised chain until it has the DOF asked for, verified.

:func:`mechanize` plans the build-up order and the ranked candidates (:mod:`linkwork.mechanization.search`),
assembles a design from the best candidates, verifies it by tracing (:mod:`linkwork.mechanization.verify`) and,
when a design fails, replaces the link blamed for the defect by its next candidate, until one passes or the
attempts run out.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from linkwork.mechanization.assemble import BinaryLink, Design
from linkwork.mechanization.chain import ShapeChain, build_chain
from linkwork.mechanization.search import (
    MechanizationError,
    MechanizeOptions,
    Plan,
    plan,
    prismatic_actuator,
    roots,
)
from linkwork.mechanization.verify import Verification, verify
from linkwork.synthesis.result import SynthesisResult


@dataclass(frozen=True)
class Mechanization:
    """A verified mechanized design and how it was found.

    Attributes
    ----------
    design
        The chain, its binary links and drive.
    verification
        DOF, the state on every profile, the traced paths.
    attempts
        Designs traced.
    rejected
        One line per rejected design: why.
    seconds
        Wall time.
    """

    design: Design
    verification: Verification
    attempts: int
    rejected: tuple[str, ...]
    seconds: float


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
            size = chain.size
            second = next(
                (
                    c.link
                    for c in step.candidates[k + 1 :]
                    if c.link.anchor != first.anchor
                    or np.linalg.norm(c.link.circle - first.circle) > 0.1 * size
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
    elif pl.pinned_root is not None:
        drive = pl.pinned_root
    else:
        drive = "D1a"
    notes = (
        f"root body {pl.root}",
        f"bodies closed by two chain joints: {', '.join(pl.paired) or 'none'}",
        f"bodies left free (extra inputs): {', '.join(pl.free) or 'none'}",
    )
    return Design(chain, tuple(links), drive, options.dof, name, notes)


def mechanize(
    result: SynthesisResult | ShapeChain, options: MechanizeOptions | None = None, *, name: str | None = None
) -> Mechanization:
    """Mechanize a synthesised chain to ``options.dof`` degrees of freedom (1 by default), verified.

    Parameters
    ----------
    result
        A synthesis result (its compound chain is used when joints were merged), or a chain already built.
    options
        Designer choices: DOF, ground region, link offsets, anchors, drive, actuator type.
    name
        The mechanism's name (default: from the problem file).

    Raises
    ------
    MechanizationError
        When no design passes: the last reason, and how many designs were tried.
    """
    started = time.perf_counter()
    options = options or MechanizeOptions()
    if options.dof < 1:
        raise MechanizationError(f"mechanize: dof {options.dof}: expected at least 1")
    if options.actuator not in ("revolute", "prismatic"):
        raise MechanizationError(
            f"mechanize: actuator {options.actuator!r}: expected 'revolute' or 'prismatic'"
        )
    if options.anchors not in ("ground", "any", "auto"):
        raise MechanizationError(
            f"mechanize: anchors {options.anchors!r}: expected 'ground', 'any' or 'auto'"
        )
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
    rejected: list[str] = []
    attempts = 0
    modes = ("ground", "any") if options.anchors == "auto" else (options.anchors,)
    for root in roots(chain, options):
        for mode in modes:
            if time.perf_counter() - started > options.time_limit:
                break
            opts = replace(options, anchors=mode)
            try:
                pl = plan(chain, root, opts)
            except MechanizationError as exc:
                rejected.append(f"root {root}, anchors {mode}: {exc}")
                continue
            found, tried = _search(chain, pl, opts, label, rejected)
            attempts += tried
            if found is not None:
                design = _with_transmissions(*found)
                return Mechanization(
                    design, found[1], attempts, tuple(rejected), time.perf_counter() - started
                )
    last = rejected[-1].split(": ", 1)[1] if rejected else "no design"
    raise MechanizationError(
        f"mechanize: no design passes after {attempts} traced ({len(rejected)} rejected); the last: {last}"
        + (f" (DOF {options.dof} asked for)" if options.dof != 1 else "")
    )


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


def _search(
    chain: ShapeChain, pl: Plan, options: MechanizeOptions, label: str, rejected: list[str]
) -> tuple[tuple[Design, Verification] | None, int]:
    """Trace designs of one plan, replacing the link blamed for each defect, until one passes."""
    choice = [0] * len(pl.steps)
    root_pair = 0
    index: dict[str, int] = {}
    count = 0 if pl.pinned_root else 2
    for i, step in enumerate(pl.steps):
        for _ in range(step.links):
            count += 1
            index[f"D{count}"] = i
    for attempt in range(1, options.attempts + 1):
        design = _design(chain, pl, root_pair, choice, options, label)
        if options.drive is not None and options.drive not in design.joint_names():
            raise MechanizationError(
                f"mechanize: unknown drive joint {options.drive!r}; joints are {', '.join(design.joint_names())}"
            )
        check = verify(design)
        if check.passed:
            return (design, check), attempt
        rejected.append(f"root {pl.root}, anchors {options.anchors}, design {attempt}: {check.reason}")
        if check.defect == "dof":
            break
        culprit = check.culprit
        if culprit in index and choice[index[culprit]] + 1 < len(pl.steps[index[culprit]].candidates) - 1:
            choice[index[culprit]] += 1
            continue
        if pl.pinned_root is None and root_pair + 1 < len(pl.root_pairs):
            root_pair += 1
            continue
        movable = [i for i, s in enumerate(pl.steps) if choice[i] + 1 < len(s.candidates) - 1]
        if not movable:
            break
        choice[movable[attempt % len(movable)]] += 1
    return None, options.attempts


__all__ = ["Mechanization", "MechanizationError", "MechanizeOptions", "mechanize"]
