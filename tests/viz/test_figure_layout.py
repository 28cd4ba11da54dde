"""Every kind of figure linkwork writes, rendered and checked as a journal would: no text leaves the canvas (no
clipped title or label), axes say their units, angle axes stay in a sensible window, and no number is printed as
"-0" or as round-off ("from 0 to -4.97e-15").

The figures are those the commands write (trace: angles, singular values, positions, deployment sequence;
synthesis: profiles, M- and C-segments, chain; mechanization: the mechanism on every profile), caught as they are
saved.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import linkwork as lw

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.text import Text  # noqa: E402

#: Slack for a text's extent against the canvas edge (pixels): anti-aliasing of a glyph's edge.
EDGE_PX = 1.0
#: "-0", "-0.0", "-0.00" standing alone, and numbers printed at round-off size (e-10 and smaller).
NEGATIVE_ZERO = re.compile(r"(?<![\w.])[-−]0(?:\.0+)?(?![\d.eE])")
ROUND_OFF = re.compile(r"\d[eE][-−]1\d")


def _texts(fig: Figure) -> list[Text]:
    """Titles, labels, legends and annotations (tick labels are judged by the drawing's tight box, which counts
    only the ticks inside the view)."""
    ticks = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis, getattr(ax, "zaxis", None)):
            if axis is not None:
                ticks |= {
                    id(lab)
                    for tick in (*axis.majorTicks, *axis.minorTicks)
                    for lab in (tick.label1, tick.label2)
                }
    return [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip() and id(t) not in ticks]


def check_figure(fig: Figure, name: str) -> list[str]:
    """The problems of one figure, as messages (empty when it is fine)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    width, height = fig.bbox.width, fig.bbox.height
    problems = []
    tight = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans)  # pixels, what is drawn
    if (
        tight.x0 < -EDGE_PX
        or tight.y0 < -EDGE_PX
        or tight.x1 > width + EDGE_PX
        or tight.y1 > height + EDGE_PX
    ):
        problems.append(f"{name}: drawing {tight.bounds} leaves the canvas {width:.0f} x {height:.0f}")
    for t in _texts(fig):
        box = t.get_window_extent(renderer)
        inside = (
            box.x0 >= -EDGE_PX
            and box.y0 >= -EDGE_PX
            and box.x1 <= width + EDGE_PX
            and box.y1 <= height + EDGE_PX
        )
        if not inside:
            problems.append(f"{name}: text {t.get_text()!r} at {box.bounds} leaves the canvas")
        text = t.get_text()
        if NEGATIVE_ZERO.search(text) or ROUND_OFF.search(text):
            problems.append(f"{name}: text {text!r} shows -0 or round-off")
    for ax in fig.axes:
        if ax.name == "3d" or not ax.axison:
            continue
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            if label and not re.search(r"\(.+\)|step|\bunit", label):
                problems.append(f"{name}: axis label {label!r} has no unit")
    return problems


@pytest.fixture
def caught(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Check every figure as it is saved; the list collects the problems."""
    problems: list[str] = []
    original = Figure.savefig

    def savefig(self: Figure, fname, *args, **kwargs):  # type: ignore[no-untyped-def]
        if str(fname).endswith(".png"):
            problems.extend(check_figure(self, Path(str(fname)).name))
        return original(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return problems


@pytest.fixture(scope="module")
def guest() -> lw.Trace:
    return lw.trace(lw.load("guest-frame"), branches=True, max_steps=3000)


def test_trace_figures_fit_their_canvas(caught: list[str], tmp_path: Path, guest: lw.Trace) -> None:
    from linkwork.outputs.trace import write_trace_outputs

    runs = {
        "guest": guest,
        "hoop": lw.trace(lw.load("hedgepeth-rods", n=6)),
        "four_bar": lw.trace(lw.load("four-bar"), drive="A", until=("A", np.radians(420.0))),
    }
    for name, path in runs.items():
        write_trace_outputs(path, tmp_path / name)
    assert (tmp_path / "four_bar" / "points.png").is_file()
    assert not caught, "\n".join(caught)


def test_angle_axes_stay_in_one_turn(guest: lw.Trace) -> None:
    """Guest's frame: its 13 branches once spanned -300 to 410 deg. Revolute joints are now plotted wrapped into
    [-180, 180) deg, the same configurations (whole turns away), the lines broken where they wrap."""
    from linkwork.viz.trace_plots import branch_degrees, broken_at_wraps

    for br in guest.branches:
        mask = guest.of_branch(br.id)
        deg = branch_degrees(guest, mask)
        assert np.all(deg >= -180.0) and np.all(deg < 180.0)
        turns = (deg - np.degrees(guest.angles[mask])) / 360.0
        np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)
        x, y = broken_at_wraps(deg[:, 0], deg[:, 1])
        steps = np.abs(np.diff(np.column_stack([x, y]), axis=0))
        assert np.nanmax(steps) < 90.0  # no line crosses the figure at a wrap


@pytest.mark.slow
def test_synthesis_and_mechanism_figures_fit_their_canvas(caught: list[str], tmp_path: Path) -> None:
    from linkwork.outputs.synthesis import run_synthesis_example

    run_synthesis_example(tmp_path / "wing", "wing", file="mechanize.toml")
    assert (tmp_path / "wing" / "mechanism.png").is_file() and (tmp_path / "wing" / "profiles.png").is_file()
    assert not caught, "\n".join(caught)


def test_the_checker_sees_a_clipped_title(tmp_path: Path) -> None:
    fig = Figure(figsize=(3.0, 2.0), dpi=100)
    ax = fig.add_subplot()
    ax.set_title("a title far too long to fit on a figure only three inches wide, so it is cut")
    ax.set_xlabel("x")
    ax.set_ylabel("-0.0")
    problems = check_figure(fig, "bad")
    assert any("leaves the canvas" in p for p in problems)
    assert any("no unit" in p for p in problems)
    assert any("-0" in p for p in problems)
