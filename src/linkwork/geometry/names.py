"""Default names of joints: ``A, B, ..., Z``, then ``A1, B1, ..., Z1``, ``A2``, ... for any number of joints."""

from __future__ import annotations


def default_joint_name(index: int) -> str:
    """The name of joint ``index`` (counted from 0) when the user gives none: ``A`` .. ``Z``, then ``A1`` .. ``Z1``,
    ``A2``, ...; distinct for every index."""
    if index < 0:
        raise ValueError(f"joint index {index}: expected 0 or more")
    letter = chr(ord("A") + index % 26)
    return letter if index < 26 else f"{letter}{index // 26}"


def default_joint_names(count: int) -> list[str]:
    """The default names of ``count`` joints, in order."""
    return [default_joint_name(i) for i in range(count)]
