"""Text a user wrote (names of linkages, joints and profiles), made safe for matplotlib.

matplotlib reads a text between two ``$`` as mathtext, and a name such as ``$x^$`` then fails to draw (a
traceback instead of a figure). :func:`plain` escapes every ``$`` so that names are always drawn as written.
"""

from __future__ import annotations

import re

__all__ = ["plain", "subscript"]


def plain(text: str) -> str:
    """``text`` drawn literally by matplotlib: each ``$`` escaped as ``\\$`` (mathtext never starts)."""
    return text.replace("$", r"\$")


def subscript(symbol: str, name: str) -> str:
    """``symbol`` with ``name`` as a subscript in mathtext (``$\\theta_{A}$``) when ``name`` is letters, digits
    and underscores (nothing mathtext could read as a command), else ``symbol`` and the plain name."""
    if re.fullmatch(r"[A-Za-z0-9]{1,12}", name):
        return rf"${symbol}_{{{name}}}$"
    return f"${symbol}$ " + plain(name)
