"""`mechanism.html`: the trace viewer of the mechanized wing, with the target profiles over it, framed on the
chain (the wing's rear arc slide turns about a centre about 15 chords away, which sets the whole-linkage view)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.mechanization import MechanizeOptions, build_chain, mechanization_dict, mechanize
from linkwork.synthesis import synthesize
from linkwork.viz.mechanism_viewer import mechanism_viewer_data, write_mechanism_viewer

WING = example("wing", "mechanize.toml")


@pytest.fixture(scope="module")
def wing() -> object:
    return mechanize(synthesize(load_problem(WING)), MechanizeOptions(designs=1))


def test_target_profiles_are_drawn_over_the_chain_in_the_fixed_view(wing: object) -> None:
    data = mechanism_viewer_data(wing)  # type: ignore[arg-type]
    chain = wing.design.chain  # type: ignore[attr-defined]
    assert data["view"] == "fixed"
    links = wing.design.links  # type: ignore[attr-defined]
    assert len(data["overlays"]) == chain.count + len(links) == 3 + len(links)
    for overlay, target in zip(data["overlays"][: chain.count], chain.targets, strict=True):
        points = np.array(overlay["points"])
        assert np.array_equal(points[:, :2], target) and np.all(points[:, 2] == 0.0)
    # then every link's moving pivot on the profiles: mechanization.json's profiles[k].pivots
    report = mechanization_dict(wing)  # type: ignore[arg-type]
    for overlay, link in zip(data["overlays"][chain.count :], links, strict=True):
        moving = [profile["pivots"][link.name][1] for profile in report["profiles"]]
        np.testing.assert_allclose(np.array(overlay["points"])[:, :2], moving, rtol=0, atol=1e-12)


def test_the_view_is_framed_on_the_chain_not_on_the_far_arc_centre(wing: object) -> None:
    data = mechanism_viewer_data(wing)  # type: ignore[arg-type]
    size = wing.design.chain.size  # type: ignore[attr-defined]
    slides = [j.point for j in build_chain(synthesize(load_problem(WING))).joints if j.role == "slide"]
    far = max(float(np.linalg.norm(p)) for p in slides)
    assert far > 10 * size  # the rear arc's centre: what made the whole-linkage view a sliver
    box = data["bounds"]["fixed"]
    lo, hi = np.array(box["min"][:2]), np.array(box["max"][:2])
    targets = np.vstack(wing.design.chain.targets)  # type: ignore[attr-defined]
    assert np.all(targets >= lo) and np.all(targets <= hi)
    report = mechanization_dict(wing)  # type: ignore[arg-type]
    pivots = np.array([p for prof in report["profiles"] for pair in prof["pivots"].values() for p in pair])
    assert np.all(pivots >= lo) and np.all(pivots <= hi)  # every link's pivots on every profile
    assert box["radius"] <= 2 * size < far / 5  # the profiles and the pivots, padded by 8 %


def test_the_page_is_self_contained_and_holds_the_overlays(wing: object, tmp_path: Path) -> None:
    page = write_mechanism_viewer(wing, tmp_path / "mechanism.html").read_text()  # type: ignore[arg-type]
    assert "drawOverlays" in page and '"view":"fixed"' in page
    payload = re.search(r'"overlays":(\[.*?\]\}\])', page)
    assert payload is not None and len(json.loads(payload.group(1))) >= 3
    assert "http://" not in page and "https://" not in page
