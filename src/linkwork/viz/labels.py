"""Numbers as figures print them: no ``-0``, no round-off shown as a value (``-4.97e-15`` is 0)."""

from __future__ import annotations

import math


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
