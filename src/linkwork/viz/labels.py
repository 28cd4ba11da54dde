"""Text in figures: numbers as figures print them (no ``-0``, no round-off shown as a value: ``-4.97e-15`` is 0),
and names a user wrote drawn as written.

matplotlib reads a text between two ``$`` as mathtext, and a name such as ``$x^$`` then fails to draw (a
traceback instead of a figure). :func:`plain` escapes every ``$`` so that names are always drawn as written.
"""

from __future__ import annotations

import math
import re

from linkwork.names import mathtext

__all__ = ["number", "plain", "plain_log_ticks", "subscript"]


def number(value: float, fmt: str = ".4g", *, scale: float = 1.0) -> str:
    """``value`` formatted with ``fmt``; anything below ``1e-9 * scale`` in size is printed as 0, and a result
    that reads as a negative zero (``-0``, ``-0.0``) loses its sign."""
    value = float(value)
    if math.isfinite(value) and abs(value) < 1e-9 * max(abs(scale), 1e-300):
        value = 0.0
    text = format(value, fmt)
    stripped = text.lstrip("-").replace("0", "").replace(".", "")
    if text.startswith("-") and stripped == "":
        text = text[1:]
    return text


def plain(text: str) -> str:
    """``text`` drawn literally by matplotlib: each ``$`` escaped as ``\\$`` (mathtext never starts); the name
    policy's :func:`linkwork.names.mathtext`."""
    return mathtext(text)


def subscript(symbol: str, name: str) -> str:
    """``symbol`` with ``name`` as a subscript in mathtext (``$\\theta_{A}$``) when ``name`` is letters and digits
    (nothing mathtext could read as a command), else ``symbol`` and the plain name."""
    if re.fullmatch(r"[A-Za-z0-9]{1,12}", name):
        return rf"${symbol}_{{{name}}}$"
    return f"${symbol}$ " + plain(name)


def plain_log_ticks(axis: object) -> None:
    """Label a log-scaled axis (``ax.xaxis`` or ``ax.yaxis``) with plain numbers (``0.001``, ``3``, ``1e-18``)
    instead of mathtext powers (``10^{-3}``, ``3x10^0``), on its major and minor ticks; matplotlib's own choice
    of which minor ticks to label is kept."""
    from matplotlib.ticker import LogFormatter

    axis.set_major_formatter(LogFormatter(labelOnlyBase=False))  # type: ignore[attr-defined]
    axis.set_minor_formatter(LogFormatter(labelOnlyBase=False, minor_thresholds=(1, 0.4)))  # type: ignore[attr-defined]
