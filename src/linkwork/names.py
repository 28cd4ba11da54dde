"""Name rules every layer shares (on the ground floor: it imports nothing of linkwork)."""

from __future__ import annotations

__all__ = ["MAX_NAME_CHARS"]

MAX_NAME_CHARS = 100
"""The longest name (of a joint, profile or linkage) accepted, in characters."""
