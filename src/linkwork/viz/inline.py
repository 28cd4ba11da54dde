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


def trace_html(trace: Trace) -> str:
    """The inline viewer of a traced motion (``Trace._repr_html_``)."""
    from linkwork.viz.viewer import trace_viewer_page

    return iframe(trace_viewer_page(trace), title=f"linkwork viewer: {trace.mechanism.name}")


def synthesis_html(result: SynthesisResult) -> str:
    """The inline viewer of a synthesis result (``SynthesisResult._repr_html_``)."""
    from linkwork.viz.viewer import synthesis_viewer_page

    return iframe(synthesis_viewer_page(result), title="linkwork viewer: synthesis")
