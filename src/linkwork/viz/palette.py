"""The one colour palette of linkwork's figures and viewers: matplotlib's tab10, so that a joint or a profile has
the same colour in a PNG figure, in the interactive viewer (which receives it in its data) and in the mechanism
drawings."""

from __future__ import annotations

TAB10 = (
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
)  # fmt: skip
"""matplotlib's ``tab10`` colours, in order."""


def colour(index: int) -> str:
    """The palette's colour for item ``index`` (cycling)."""
    return TAB10[index % len(TAB10)]


PROFILE_COLORS = tuple(TAB10[i] for i in (0, 3, 2, 1, 4, 5, 6, 9))
"""The colours of target profiles 1, 2, 3, ... in the synthesis figures: eight of the tab10 colours, in the order
those figures use (blue, red, green, orange, purple, brown, pink, cyan)."""
