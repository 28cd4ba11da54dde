"""A design whose links make a group of the chain rigid (frozen) is refused before tracing, naming the joints; the
joint pivot fit proposes configurations that the kinematic core's own closure equations accept.

Checked against what the verification does not compute itself: the frozen joints are those whose relative motion
is fixed by counting (two links from ``s2a`` to ``s3`` with the arc slide ``S2`` and the joint ``J2`` leave
``s2b`` and ``s3`` no motion relative to ``s2a``: 6 unknowns, 6 constraints); the fitted configurations close
the mechanism's loops by :func:`linkwork.kinematics.closure.closure_residual`, and each fitted link's
structural error is the spread of the distance between its pivots in the chain's own poses (six NACA camber
lines).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.geometry.se2 import relative
from linkwork.io.problem import load_problem
from linkwork.kinematics.closure import closure_residual
from linkwork.mechanization import MechanizeOptions, mechanize
from linkwork.mechanization.chain import track
from linkwork.mechanization.guidance import centre_point
from linkwork.mechanization.pivot_fit import fit_pivots
from linkwork.mechanization.verify import verify
from linkwork.synthesis import synthesize


@pytest.fixture(scope="module")
def wing():
    """The bundled wing mechanized (three profiles, exact links)."""
    return mechanize(synthesize(load_problem(example("wing", "mechanize.toml"))), MechanizeOptions(designs=1))


def test_two_links_from_the_body_a_pair_hangs_from_freeze_it_and_the_verification_says_which_joints(
    wing,
) -> None:
    design = wing.design
    chain = design.chain
    kept = [link for link in design.links if link.body not in ("s2b", "s3")]
    assert len(kept) == len(design.links) - 2  # the wing's design guides s2b and s3 by one link each
    rel = relative(chain.motion("s2a"), chain.motion("s3"))
    outline = chain.body("s3").outline
    pair = []
    for k, m in enumerate((outline[0], outline[-1])):
        # the exact dyad's centre moved off by 5 % of the size: exact pairs make a special (shaky) geometry, a
        # generic pair (as least squares gives with more profiles) makes the group rigid
        dyad = centre_point(rel, m)
        dyad = replace(dyad, centre_point=dyad.centre_point + 0.05 * chain.size * np.array([1.0, -0.5 + k]))
        pair.append(
            replace(
                kept[0],
                name=f"D{len(design.links) + k + 1}",
                kind="RR",
                anchor="s2a",
                body="s3",
                centre=dyad.centre_point,
                circle=dyad.circle_point,
                structural_error=0.0,
                via=None,
            )
        )
    frozen = replace(design, links=(*kept, *pair))
    check = verify(frozen)
    assert check.dof == 1 and not check.passed and check.defect == "frozen", check.reason
    named = set(check.reason.split("joints ")[1].split(" cannot")[0].split(", "))
    assert named == {"S2", "J2"}, check.reason  # s2b and s3 rigid on s2a; J1, J3, S4 still move
    assert check.culprit in {link.name for link in pair}


def test_the_search_refuses_a_drive_no_design_of_the_chain_has(wing) -> None:
    from linkwork.errors import SpecError

    result = synthesize(load_problem(example("wing", "mechanize.toml")))
    with pytest.raises(SpecError, match=r"D1 \.\.\. D7"):
        mechanize(result, MechanizeOptions(drive="D8m"))
    assert "D7m" in {n for link in wing.design.links for n in link.joint_names()}


@pytest.mark.slow
def test_fitted_pivots_give_configurations_the_mechanism_closes_and_honest_structural_errors(
    tmp_path: Path,
) -> None:
    from .test_profile_families import CAMBER_LINES, _problem

    result = synthesize(load_problem(_problem(tmp_path, CAMBER_LINES)))  # six NACA camber lines
    found = mechanize(result, MechanizeOptions(designs=1))
    design = found.design
    chain = design.chain
    limit = MechanizeOptions().structural_limit(chain.size)
    fitted = fit_pivots(design, limit, MechanizeOptions().min_transmission, 1.5 * chain.size, evaluations=60)
    mech = fitted.mechanism()
    values = fitted.expected_values()
    for j in range(chain.count):
        # the fitted configuration is on the mechanism: its loops close to a thousandth of the size (the joints
        # and lengths are weighted residuals of a fit stopped after 60 evaluations; another assembly or a link
        # off its length would leave a tenth); the verification traces it anyway
        assert np.linalg.norm(closure_residual(mech, values[j])) <= 1e-3 * chain.size, j
    for link in fitted.links:
        need = np.linalg.norm(
            track(chain.motion(link.body), link.circle) - track(chain.motion(link.anchor), link.centre),
            axis=1,
        )
        assert abs(np.ptp(need) - link.structural_error) <= 1e-12
        assert link.structural_error <= limit * (1 + 1e-6) and link.length <= 1.5 * chain.size
    # the fit minimises the sum of squared point errors over the later profiles: its configurations are nearer
    # the profiles in that sense than the unfitted design as traced (pivots as found, configurations on the
    # mechanism: a feasible point of the same problem; measured 6.7e-4 against 9.1e-4)
    from linkwork.mechanization.verify import chain_displacements

    assert fitted.fitted is not None
    poses = fitted.fitted
    fit_cost = sum(
        float(np.sum(chain.errors({b: g[j] for b, g in poses.items()}, j) ** 2))
        for j in range(1, chain.count)
    )
    unfitted = design.mechanism()
    traced_cost = sum(
        float(np.sum(chain.errors(chain_displacements(design, unfitted, state.values), j) ** 2))
        for j, state in enumerate(found.verification.states)
        if j > 0
    )
    assert fit_cost <= traced_cost
