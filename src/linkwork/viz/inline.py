"""The offline viewer inline in a notebook: a viewer page embedded in an ``<iframe srcdoc>``.

The page is the same self-contained file ``--html`` writes (:mod:`linkwork.viz.viewer`); as the value of an
HTML attribute it is escaped whole (``&``, ``<``, ``>``, both quotes), so nothing a user wrote (a mechanism's or a
profile's name) can leave the attribute. The frame is sandboxed: its scripts run, with no access to the notebook.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from linkwork.names import html_text

if TYPE_CHECKING:
    from linkwork.kinematics.trace_result import Trace
    from linkwork.synthesis.result import SynthesisResult

HEIGHT = 620
"""Height of the inline viewer in CSS pixels (its width follows the notebook's)."""


def iframe(page: str, *, title: str, height: int = HEIGHT) -> str:
    """An ``<iframe>`` element showing the HTML document ``page``."""
    return (
        f'<iframe srcdoc="{html_text(page)}" title="{html_text(title)}" '
        f'sandbox="allow-scripts" style="width: 100%; height: {int(height)}px; border: 1px solid #ddd;">'
        "</iframe>"
    )


INLINE_BYTES = 280_000
"""The most characters of a trace's inline viewer: a notebook holding several stays light. The path shown is
thinned evenly to fit (its ends and bifurcation points kept); the :class:`Trace` keeps every point, and
``linkwork trace --html`` (or :func:`linkwork.viz.viewer.write_trace_viewer`) writes the full page."""

INLINE_POINTS = 400
"""Points of the path the inline viewer shows at most, before the size check."""


def trace_html(trace: Trace) -> str:
    """The inline viewer of a traced motion (``Trace._repr_html_``), under :data:`INLINE_BYTES`."""
    from linkwork.viz.viewer import trace_viewer_page

    title = f"linkwork viewer: {trace.mechanism.name}"
    points = min(INLINE_POINTS, len(trace.branch))
    page = iframe(trace_viewer_page(trace, max_points=points), title=title)
    fewest = 2 * max(1, len(trace.branches))  # both ends of every branch
    while len(page) > INLINE_BYTES and points > fewest:
        points = max(fewest, int(points * 0.6))
        page = iframe(trace_viewer_page(trace, max_points=points), title=title)
    if (
        len(page) > INLINE_BYTES
    ):  # the solids alone are too large (a hoop of many rods): say so, in a few lines
        return (
            f"<pre>{html_text(repr(trace))}</pre><p>The interactive viewer of this linkage is "
            f"{len(page) // 1000} kB even with its path thinned to {points} points, too large to embed: write it "
            "with <code>linkwork.viz.viewer.write_trace_viewer(trace, 'viewer.html')</code> or "
            "<code>linkwork trace --html</code>.</p>"
        )
    return page


def synthesis_html(result: SynthesisResult) -> str:
    """The inline viewer of a synthesis result (``SynthesisResult._repr_html_``)."""
    from linkwork.viz.viewer import synthesis_viewer_page

    return iframe(synthesis_viewer_page(result), title="linkwork viewer: synthesis")
