"""What a notebook shows of a result: a short ``repr``, the offline viewer inline (escaped whole into an iframe's
``srcdoc``), ``.plot()`` Figures drawing the result's own numbers; and radians for built-in parameters."""

from __future__ import annotations

import html
import re
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.figure import Figure

import linkwork as lw
from linkwork.data import example
from linkwork.io.spec import resolve_spec
from linkwork.viz.viewer import synthesis_viewer_page, trace_viewer_page


@pytest.fixture(scope="module")
def frame() -> lw.Trace:
    return lw.trace(lw.load("guest-frame"), branches=True, max_steps=1500)


@pytest.fixture(scope="module")
def wing() -> object:
    return lw.synthesize(example("wing", "mechanize.toml"))


def test_reprs_are_a_few_short_lines(frame: lw.Trace, wing: object) -> None:
    big = lw.trace(lw.load("hedgepeth-rods", n=24), until=("A", np.radians(20.0)))
    for text in (repr(frame), repr(big), repr(wing)):
        lines = text.splitlines()
        assert 3 <= len(lines) < 10
        assert max(len(line) for line in lines) <= 120
    assert len(frame.branches) > 4 and "more branches" in repr(frame)
    assert f"{len(frame.angles)} points" in repr(frame)
    assert "design MCMC" in repr(wing)


def _srcdoc(markup: str) -> str:
    match = re.fullmatch(
        r'<iframe srcdoc="([^"]*)" title="([^"]*)" sandbox="allow-scripts" style="[^"]*"></iframe>', markup
    )
    assert match, markup[:200]
    return html.unescape(match.group(1))


def test_the_inline_viewer_is_the_offline_page_escaped_whole(wing: object) -> None:
    bennett = lw.trace(lw.load("bennett"), until=("A", np.radians(90.0)))
    assert _srcdoc(bennett._repr_html_()) == trace_viewer_page(bennett)
    assert _srcdoc(wing._repr_html_()) == synthesis_viewer_page(wing)  # type: ignore[attr-defined, arg-type]


def test_a_hostile_name_stays_inside_the_attribute() -> None:
    mech = lw.load("bennett")
    evil = replace(mech, name='"><script>alert(1)</script><b title="')
    markup = lw.trace(evil, until=("A", mech.offsets[0] + 0.2))._repr_html_()
    assert "<script" not in markup and "<b " not in markup
    assert markup.count('"') == 8  # the quotes of srcdoc, title, sandbox and style only


def test_trace_plots_draw_the_traced_angles(frame: lw.Trace) -> None:
    figure = frame.plot()
    assert isinstance(figure, Figure)
    (ax,) = figure.axes
    d = frame.mechanism.index(frame.drive)
    first = ax.lines[0]  # branch 0, the first joint other than the drive
    mask = frame.of_branch(0)
    # revolute angles are drawn wrapped into [-180, 180), the line broken (NaN) where it wraps
    x, y = (np.asarray(v, dtype=float) for v in (first.get_xdata(), first.get_ydata()))
    drawn = ~np.isnan(x)
    assert drawn.sum() == mask.sum()
    wrapped = (np.degrees(frame.angles[mask][:, [d, 1]]) + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(x[drawn], wrapped[:, 0], atol=1e-9)
    np.testing.assert_allclose(y[drawn], wrapped[:, 1], atol=1e-9)
    sv = frame.plot("singular_values", branch=0)
    assert isinstance(sv, Figure) and len(sv.axes) == 2
    np.testing.assert_allclose(sv.axes[0].lines[0].get_ydata(), frame.sigma[mask, 0], atol=0)
    with pytest.raises(ValueError, match="Expected kind"):
        frame.plot("nope")


def test_synthesis_plots(wing: object) -> None:
    for kind in ("chain", "profiles", "errors"):
        assert isinstance(wing.plot(kind), Figure)  # type: ignore[attr-defined]
    (ax,) = wing.plot("errors").axes  # type: ignore[attr-defined]
    joined = wing.joined_error_matrix  # type: ignore[attr-defined]
    solid = sorted(p.get_height() for p in ax.patches if p.get_alpha() is None)
    np.testing.assert_allclose(solid, np.sort(joined.ravel()), atol=0)
    with pytest.raises(ValueError, match="Expected kind"):
        wing.plot("nope")  # type: ignore[attr-defined]


def test_built_in_parameters_are_radians_in_the_api() -> None:
    # The same Bennett linkage from the API (radians) and from the command line's --set (degrees).
    api = lw.load("bennett", alpha1=np.radians(30.0), theta=np.radians(50.0), scale=2.0)
    flag = resolve_spec("bennett", {"alpha1": 30, "theta": 50, "scale": 2.0}).mechanism
    np.testing.assert_allclose(api.twists, flag.twists, atol=1e-14)
    np.testing.assert_allclose(api.offsets, flag.offsets, atol=1e-14)
    assert api.meta["alpha1"] == pytest.approx(np.radians(30.0), abs=1e-15)
