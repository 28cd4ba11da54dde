"""What a notebook shows: every documented ``plot(kind)`` works on the bundled examples; a mechanism has a short
repr and an HTML card (its joints and bodies, and a drawing); a branched trace's repr describes each branch as
traced; and a trace's inline viewer stays under 300 kB for every built-in while the trace keeps every point."""

from __future__ import annotations

import html
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import linkwork as lw
from linkwork.linkages import REGISTRY

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.figure import Figure  # noqa: E402

#: The inline viewer's limit (characters of the HTML) the issue asks for.
INLINE_LIMIT = 300_000
#: The plot kinds the README and the docstrings document.
TRACE_KINDS = ("angles", "singular_values")
SYNTHESIS_KINDS = ("chain", "profiles", "errors", "compound")


@pytest.fixture(scope="module")
def guest() -> lw.Trace:
    return lw.trace(lw.load("guest-frame"), branches=True)


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_every_trace_plot_kind_draws_every_built_in(name: str) -> None:
    traced = lw.trace(lw.load(name), max_steps=60)
    for kind in TRACE_KINDS:
        fig = traced.plot(kind)
        assert isinstance(fig, Figure) and fig.axes and any(ax.lines for ax in fig.axes)


@pytest.mark.parametrize(
    "example",
    ["wing", *(pytest.param(e, marks=pytest.mark.slow) for e in ("closed", "fixed-end", "seat", "wing-six"))],
)
def test_every_synthesis_plot_kind_draws_the_bundled_examples(example: str) -> None:
    """``result.plot("compound")`` raised ValueError on the README's wing (no compound stage, merge_below = 0);
    it now draws the joined chain with each joint's range of motion, and the compound stage when there is one."""
    result = lw.synthesize(example)
    for kind in SYNTHESIS_KINDS:
        fig = result.plot(kind)
        assert isinstance(fig, Figure) and any(ax.lines for ax in fig.axes), kind
    labels = [t.get_text() for t in result.plot("compound").axes[0].texts]
    assert len(labels) == len(result.segments) - 1  # every inner joint labelled with its range (Eq. 34)
    with pytest.raises(ValueError, match="Expected kind one of"):
        result.plot("nonsense")


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_a_mechanism_prints_in_one_short_line_and_has_an_html_card(name: str) -> None:
    mech = lw.load(name)
    text = repr(mech)
    assert "\n" not in text and len(text) < 200 and "array(" not in text
    assert repr(mech.name) in text and f"{mech.n_joints} " in text
    card = mech._repr_html_()
    assert len(card) < 20_000
    root = ET.fromstring(f"<root>{card}</root>")  # well-formed: every tag closed, every name escaped
    cells = [td.text for td in root.iter("td") if td.text]
    for joint in mech.joint_names:
        assert joint in cells
    for body in mech.bodies:
        assert body in cells
    svg = root.find(".//{http://www.w3.org/2000/svg}svg")
    assert svg is not None
    circles = svg.findall("{http://www.w3.org/2000/svg}circle")
    assert len(circles) == mech.n_joints


def test_a_hostile_name_stays_text_in_the_card() -> None:
    from dataclasses import replace

    mech = replace(lw.load("four-bar"), name="<script>alert(1)</script>")
    card = mech._repr_html_()
    assert "<script>" not in card and html.escape("<script>") in card


def test_a_branched_trace_describes_each_branch(guest: lw.Trace) -> None:
    """Guest's frame said "drive A from 0 to 38.9424 deg" (the first point of branch 0 and the last of the last
    branch); each branch line now gives what moved on that branch, as the data have it."""
    text = repr(guest)
    assert "from 0 to 38.9424" not in text
    drive = np.degrees(guest.angles[:, guest.mechanism.index(guest.drive)])
    assert f"over {drive.min():.6g} to {drive.max():.6g} deg on all branches" in text
    for br in guest.branches[:4]:
        line = next(x for x in text.splitlines() if x.strip().startswith(f"branch {br.id}:"))
        values = np.degrees(guest.angles[guest.branch == br.id])
        moved = re.findall(r"(\w+) (-?[\d.e+-]+) -> (-?[\d.e+-]+) deg", line)
        assert moved, line
        for joint, first, last in moved:
            j = guest.mechanism.index(joint)
            assert float(first) == pytest.approx(values[0, j], abs=0.01)  # printed with 5 digits
            assert float(last) == pytest.approx(values[-1, j], abs=0.01)


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_the_inline_viewer_stays_small_for_every_built_in(name: str) -> None:
    """Guest's frame's inline page was 1.12 MB; the path shown is thinned, the trace keeps every point."""
    traced = lw.trace(lw.load(name), branches=True)
    before = len(traced.angles)
    page = traced._repr_html_()
    assert len(page) < INLINE_LIMIT, f"{name}: {len(page)} characters"
    assert len(traced.angles) == before
    assert f"&quot;points_traced&quot;: {before}" in page or f"&quot;points_traced&quot;:{before}" in page


def test_a_linkage_too_large_to_embed_gets_a_short_note(monkeypatch: pytest.MonkeyPatch) -> None:
    """When even the thinned viewer is over the limit (the solids of a hoop of many rods), the inline form is the
    summary and where to find the full viewer, not a page over the limit."""
    from linkwork.viz import inline

    monkeypatch.setattr(inline, "INLINE_BYTES", 50_000)  # below the viewer's own size
    traced = lw.trace(lw.load("bennett"), max_steps=40)
    page = traced._repr_html_()
    assert len(page) < 50_000 and "write_trace_viewer" in page and html.escape(traced.mechanism.name) in page
