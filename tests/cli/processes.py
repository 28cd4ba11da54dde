"""The ``linkwork`` command as a separate process, for the tests that send it signals: the installed script
(skipped when it is not installed) and an environment that imports this tree and draws no colours."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest


def linkwork_command(args: list[str]) -> list[str]:
    """The command line running the installed ``linkwork`` script with ``args``."""
    script = Path(sys.executable).with_name("linkwork")
    if not script.exists():
        pytest.skip("the linkwork script is not installed")
    return [str(script), *args]


def process_env(**extra: str) -> dict[str, str]:
    """This process's environment, with its import path (the tree under test), no colours, unbuffered output,
    and ``extra``."""
    return {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(sys.path),
        "NO_COLOR": "1",
        "PYTHONUNBUFFERED": "1",
        **extra,
    }
