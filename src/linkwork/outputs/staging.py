"""Safe output for the commands' summaries and folders: the console every summary is printed on, and the one
writer (:mod:`linkwork.io.writer`: staging, ownership through the manifest, no writing through links), re-exported
here for the output modules."""

from __future__ import annotations

from rich.console import Console

from linkwork.io.writer import MANIFEST, check_output_file, check_output_folder, staged_output, write_file

__all__ = [
    "MANIFEST",
    "check_output_file",
    "check_output_folder",
    "console",
    "have_matplotlib",
    "staged_output",
    "write_file",
]

console = Console(markup=False)
"""The console every summary is printed on (standard output). Markup is off: names, files and notes a user wrote
are printed as text (``[/]`` in a joint name is two brackets and a slash); styled words are :class:`rich.text.Text`."""


def have_matplotlib() -> bool:
    """True when the optional plotting extra (``linkwork[viz]``) is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True
