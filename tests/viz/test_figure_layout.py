"""Every figure the CLI writes, rendered and checked as a journal would, from the matplotlib objects: no text
leaves the canvas (no clipped title or label); every axis that shows numbers says its quantity and its unit in
brackets or parentheses; no legend covers plotted data (lines, markers, band and bar outlines); log axes read in
plain numbers (no mathtext powers such as "3x10^0"); no number is printed as "-0" or as round-off; and no plotted
series jumps where its data do not (one step far larger than its neighbouring steps: a wrapped angle drawn
across the figure, a bad last value).

The commands are run as a user runs them (trace, synth, mechanize, robustness, sweep, and ``search`` when it is
there), every figure they save is caught and checked, and every PNG they leave in their folder must have been
checked: a figure added to a command later is covered without touching this file.
"""

from __future__ import annotations

import itertools
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
        for axis in (ax.xaxis, ax.yaxis):
            if not axis.get_visible() or not _shown_ticks(axis):
                continue  # a twin's shared axis, a panel whose tick labels its neighbour shows
            label = axis.get_label_text()
            if not UNIT.search(label):
                problems.append(f"{name}: axis label {label!r} has no quantity and unit in brackets")
            powers = [t for t in _shown_ticks(axis) if MATHTEXT_POWER.search(t)]
            if powers or MATHTEXT_POWER.search(axis.get_offset_text().get_text()):
                problems.append(f"{name}: {label!r} ticks read as powers {powers[:3]}, not plain numbers")
        problems += [f"{name}: {p}" for p in jumps(ax)]
    problems += [f"{name}: {p}" for p in legends_over_data(fig, renderer)]
    return problems


#: A quantity and its unit: something in parentheses or brackets after the name, e.g. "hinge angle (deg)".
UNIT = re.compile(r"\w.*[(\[][^)\]]*\S[^)\]]*[)\]]")
#: A tick label in mathtext powers ("$\mathdefault{10^{-3}}$", "$3\times10^{0}$").
MATHTEXT_POWER = re.compile(r"\$.*(\^|\\times).*\$")
#: A step of a plotted line this many times its neighbours' (median) is a jump, when it also spans more than
#: JUMP_SPAN of the axes.
JUMP_RATIO = 10.0
JUMP_SPAN = 0.08
#: Neighbouring steps on each side that a step is compared with; lines with fewer points are not judged.
JUMP_WINDOW = 6
JUMP_MIN_POINTS = 8
#: Spacing (pixels) of the points a line is sampled at between its vertices for the legend check.
SAMPLE_PX = 2.0


def _shown_ticks(axis) -> list[str]:  # type: ignore[no-untyped-def]
    """The texts of the tick labels an axis draws (inside its view)."""
    low, high = sorted(axis.get_view_interval())
    texts = []
    for tick in (*axis.get_major_ticks(), *axis.get_minor_ticks()):
        loc = tick.get_loc()
        if loc is None or not low - 1e-12 * abs(low) <= loc <= high + 1e-12 * abs(high):
            continue
        for lab in (tick.label1, tick.label2):
            if lab.get_visible() and lab.get_text().strip():
                texts.append(lab.get_text())
    return texts


def _line_segments(ax) -> list[np.ndarray]:  # type: ignore[no-untyped-def]
    """Every plotted line of ``ax`` in axes coordinates (0..1 across the view, log scales applied), split
    where the line is broken (NaN)."""
    out = []
    to_axes = ax.transAxes.inverted()
    for line in ax.get_lines():
        if not line.get_visible() or line.get_linestyle() in ("None", "none", " ", ""):
            continue
        xy = np.asarray(line.get_xydata(), dtype=float)
        if len(xy) < 2:
            continue
        with np.errstate(all="ignore"):
            pts = to_axes.transform(line.get_transform().transform(xy))
        finite = np.all(np.isfinite(pts), axis=1)
        breaks = np.flatnonzero(np.diff(finite.astype(int)) != 0) + 1
        for piece, ok in zip(np.split(pts, breaks), np.split(finite, breaks), strict=True):
            if ok.all() and len(piece) >= 2:
                out.append(piece)
    return out


def jumps(ax) -> list[str]:  # type: ignore[no-untyped-def]
    """Plotted steps far larger than the same line's neighbouring steps (see :data:`JUMP_RATIO`)."""
    found = []
    for piece in _line_segments(ax):
        if len(piece) < JUMP_MIN_POINTS:
            continue
        steps = np.linalg.norm(np.diff(piece, axis=0), axis=1)
        for i, step in enumerate(steps):
            if step < JUMP_SPAN:
                continue
            around = np.concatenate([steps[max(0, i - JUMP_WINDOW) : i], steps[i + 1 : i + 1 + JUMP_WINDOW]])
            if step > JUMP_RATIO * max(float(np.median(around)), 1e-3):
                found.append(
                    f"a line jumps by {step:.2f} of the axes at its point {i + 1} of {len(piece)} "
                    f"(neighbouring steps {np.median(around):.3g}) in {ax.get_ylabel()!r}"
                )
                break
    return found


def _densified(points: np.ndarray) -> np.ndarray:
    """Points along a polyline (display coordinates) every :data:`SAMPLE_PX` pixels, vertices included."""
    out = [points[:1]]
    for a, b in itertools.pairwise(points):
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            continue
        n = int(min(np.linalg.norm(b - a) / SAMPLE_PX, 2000)) + 1
        out.append(a + np.outer(np.linspace(0.0, 1.0, n + 1)[1:], b - a))
    return np.concatenate(out)


def _data_points(ax) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Display coordinates of what ``ax`` plots: lines and their markers, scatter points, the outlines of bands
    (fill_between) and bars, inside the axes' box."""
    from matplotlib.collections import PathCollection, PolyCollection

    clouds = [np.zeros((0, 2))]
    for line in ax.get_lines():
        if line.get_visible() and len(line.get_xydata()):
            with np.errstate(all="ignore"):
                clouds.append(
                    _densified(line.get_transform().transform(np.asarray(line.get_xydata(), float)))
                )
    for coll in ax.collections:
        if not coll.get_visible():
            continue
        if isinstance(coll, PathCollection) and len(coll.get_offsets()):
            clouds.append(coll.get_offset_transform().transform(np.asarray(coll.get_offsets(), float)))
        elif isinstance(coll, PolyCollection):
            for path in coll.get_paths():
                clouds.append(_densified(coll.get_transform().transform(path.vertices)))
    for patch in ax.patches:
        if patch.get_visible():
            clouds.append(_densified(patch.get_transform().transform(patch.get_path().vertices)))
    pts = np.concatenate(clouds)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    box = ax.bbox
    inside = (pts[:, 0] >= box.x0) & (pts[:, 0] <= box.x1) & (pts[:, 1] >= box.y0) & (pts[:, 1] <= box.y1)
    return pts[inside]


def legends_over_data(fig: Figure, renderer) -> list[str]:  # type: ignore[no-untyped-def]
    """Legends (of an axes or of the figure) whose box covers a plotted point of any 2-D axes."""
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)
    flat = [ax for ax in fig.axes if ax.name != "3d" and ax.axison]
    found = []
    for legend in legends:
        if not legend.get_visible():
            continue
        box = legend.get_window_extent(renderer).padded(-1.0)
        for ax in flat:
            pts = _data_points(ax)
            covered = (
                (pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)
            )
            if covered.any():
                labels = [t.get_text() for t in legend.get_texts()][:3]
                found.append(f"the legend {labels} covers {int(covered.sum())} plotted points")
                break
    return found


@pytest.fixture
def caught(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Check every figure as it is saved; the list collects the problems."""
    problems: list[str] = []
    original = Figure.savefig

    def savefig(self: Figure, fname, *args, **kwargs):  # type: ignore[no-untyped-def]
        if str(fname).endswith(".png"):
            problems.extend(check_figure(self, Path(str(fname)).name))
            CHECKED.append(Path(str(fname)).name)
        return original(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return problems


@pytest.fixture(scope="module")
def guest() -> lw.Trace:
    return lw.trace(lw.load("guest-frame"), branches=True, max_steps=3000)


TINY_STUDY = """name = "tiny"
linkage = "bennett"
[grid]
alpha1 = [30, 45]
alpha2 = [70, 90]
[robustness]
samples = 8
hinge_position_tol = 0.001
hinge_direction_tol = 0.05
"""
LINE_STUDY = TINY_STUDY.replace("alpha2 = [70, 90]\n", "")
SEARCH_STUDY = TINY_STUDY.split("[robustness]")[0] + "[criteria]\nmobility = 1\n"

ROBUSTNESS = ["robustness", "--samples", "16", "--workers", "0", "--hinge-position-tol", "1e-3"]
ROBUSTNESS += ["--hinge-direction-tol", "0.05"]

ROBUSTNESS = ["robustness", "--samples", "16", "--workers", "0", "--hinge-position-tol", "1e-3"]
ROBUSTNESS += ["--hinge-direction-tol", "0.05"]

#: A run of a command that writes figures: its arguments (``OUT`` is its output folder) and the study file it
#: needs, if any. (The jump check caught Guest's frame's wrong last singular values, and the four-bar's and
#: slider-crank's at a target landed on with a progress callback, until the tracing bookkeeping was fixed.)
RUNS = {
    "trace-guest-frame": (["trace", "guest-frame", "--branches", "--max-steps", "3000", "-o", "OUT"], None),
    "trace-hexagon": (
        ["trace", "hedgepeth-rods", "--set", "n=6", "--until", "A=128.6822", "-o", "OUT"],
        None,
    ),
    "trace-four-bar": (["trace", "four-bar", "--drive", "A", "--until", "A=420", "-o", "OUT"], None),
    "trace-slider-crank": (["trace", "slider-crank", "-o", "OUT"], None),
    "trace-bennett": (["trace", "bennett", "-o", "OUT"], None),
    "robustness": (
        [
            *ROBUSTNESS,
            "hedgepeth-rods",
            "--set",
            "n=6",
            "--until",
            "A=128.6822",
            "--steps",
            "60",
            "-o",
            "OUT",
        ],
        None,
    ),
    "robustness-closed-path": ([*ROBUSTNESS, "four-bar", "-o", "OUT"], None),
    "sweep-heat-map": (["sweep", "STUDY", "--workers", "0", "-o", "OUT"], TINY_STUDY),
    "sweep-lines": (["sweep", "STUDY", "--workers", "0", "-o", "OUT"], LINE_STUDY),
    "synth": (["synth", "wing", "-o", "OUT"], None),
    "search": (["search", "STUDY", "-o", "OUT"], SEARCH_STUDY),
}


def run_and_check(args: list[str], study: str | None, folder: Path, caught: list[str]) -> list[str]:
    """Run a command in-process, and return the problems of every figure it saved; every PNG it left in its
    folder must have been checked."""
    from typer.testing import CliRunner

    from linkwork.cli import app

    out = folder / "out"
    if study is not None:
        (folder / "study.toml").write_text(study)
    words = [str(out) if a == "OUT" else str(folder / "study.toml") if a == "STUDY" else a for a in args]
    checked_before = len(CHECKED)
    result = CliRunner().invoke(app, words)
    assert result.exit_code == 0, (words, result.stderr[-2000:], result.exception)
    written = {p.name for p in out.rglob("*.png")}
    if not written and args[0] == "search":
        pytest.skip("`linkwork search` wrote no figure")
    assert written, f"{args[0]} wrote no figure"
    assert written <= set(CHECKED[checked_before:]), f"not checked: {written - set(CHECKED[checked_before:])}"
    return list(caught)


#: Names of the figures checked so far (the ``caught`` fixture appends).
CHECKED: list[str] = []


#: Runs whose figures are of a kind another run already checks (still run in CI, marked slow).
SLOW_RUNS = {"trace-slider-crank", "robustness-closed-path", "sweep-lines"}


@pytest.mark.parametrize(
    "run", [pytest.param(k, marks=pytest.mark.slow) if k in SLOW_RUNS else k for k in RUNS]
)
def test_every_figure_a_command_writes_reads_well(caught: list[str], tmp_path: Path, run: str) -> None:
    args, study = RUNS[run]
    if args[0] == "search":
        from linkwork.cli import app

        if "search" not in {c.name for c in app.registered_commands}:
            pytest.skip("no `linkwork search` command in this version")
    problems = run_and_check(args, study, tmp_path, caught)
    assert not problems, "\n".join(problems)


@pytest.mark.slow
def test_synthesis_and_mechanism_figures_read_well(caught: list[str], tmp_path: Path) -> None:
    problems = run_and_check(["synth", "wing/mechanize.toml", "-o", "OUT"], None, tmp_path, caught)
    assert (tmp_path / "out" / "mechanism.png").is_file() and (tmp_path / "out" / "profiles.png").is_file()
    assert not problems, "\n".join(problems)


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


def test_the_checker_sees_a_clipped_title(tmp_path: Path) -> None:
    fig = Figure(figsize=(3.0, 2.0), dpi=100)
    ax = fig.add_subplot()
    ax.set_title("a title far too long to fit on a figure only three inches wide, so it is cut")
    ax.set_xlabel("x")
    ax.set_ylabel("-0.0")
    problems = check_figure(fig, "bad")
    assert any("leaves the canvas" in p for p in problems)
    assert any("no quantity and unit" in p for p in problems)
    assert any("-0" in p for p in problems)


def _figure_with(plot) -> Figure:  # type: ignore[no-untyped-def]
    fig = Figure(figsize=(5.0, 3.5), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    plot(ax)
    ax.set_xlabel("drive A (deg)")
    ax.set_ylabel("misfit (length unit)")
    return fig


def test_the_checker_passes_a_clean_figure() -> None:
    def plot(ax) -> None:  # type: ignore[no-untyped-def]
        x = np.linspace(0.0, 120.0, 100)
        ax.plot(x, np.sin(np.radians(x)), label="sine")
        ax.legend(loc="lower center")
        ax.set_ylim(-1.5, 1.2)

    assert check_figure(_figure_with(plot), "clean") == []


def test_the_checker_sees_a_legend_over_the_data() -> None:
    def plot(ax) -> None:  # type: ignore[no-untyped-def]
        x = np.linspace(0.0, 1.0, 50)
        for k in range(6):
            ax.plot(x, x + 0.1 * k, label=f"curve {k}")
        ax.legend(loc="center")

    assert any("covers" in p for p in check_figure(_figure_with(plot), "covered"))


def test_the_checker_sees_mathtext_powers_on_a_log_axis() -> None:
    """The misfit bands' ratio axis read "3x10^0"; plain_log_ticks writes 3."""
    from linkwork.viz.labels import plain_log_ticks

    def plot(ax) -> None:  # type: ignore[no-untyped-def]
        ax.semilogy([0, 1, 2], [2.0, 3.0, 5.0])

    assert any("powers" in p for p in check_figure(_figure_with(plot), "powers"))
    fig = _figure_with(plot)
    plain_log_ticks(fig.axes[0].yaxis)
    assert check_figure(fig, "plain") == []
    assert "3" in _shown_ticks(fig.axes[0].yaxis)


def test_the_checker_sees_a_jump_the_data_do_not_have(guest: lw.Trace) -> None:
    """Two real cases: an angle plotted without breaking it where it wraps (a line across the figure), and a
    singular value that is wrong at a branch's last point (Guest's frame: 1.41 where the neighbouring steps are
    about 0.013)."""

    def wrapped(ax) -> None:  # type: ignore[no-untyped-def]
        x = np.linspace(0.0, 720.0, 200)
        ax.plot(x, (x + 180.0) % 360.0 - 180.0)

    assert any("jumps" in p for p in check_figure(_figure_with(wrapped), "wrapped"))

    def spike(ax) -> None:  # type: ignore[no-untyped-def]
        s = guest.sigma[guest.branch == 0].copy()
        s[-1, 0] += 1.4  # the size of the jump Guest's figure showed
        ax.plot(np.arange(len(s)), s[:, 0])

    assert any("jumps" in p for p in check_figure(_figure_with(spike), "spike"))

    def smooth(ax) -> None:  # type: ignore[no-untyped-def]
        s = guest.sigma[guest.branch == 0]
        ax.plot(np.arange(len(s) - 1), s[:-1, 0])

    assert not any("jumps" in p for p in check_figure(_figure_with(smooth), "smooth"))
