"""Interrupted work never leaves a half-written output or a staging folder: SIGTERM and Ctrl-C during the
writing of a command's files, and during ``linkwork demo``, leave --out as it was."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from linkwork.interrupts import in_compiler
from linkwork.outputs.staging import MANIFEST, staged_output

INTERRUPTED_WRITER = textwrap.dedent(
    """
    import os, signal, sys, time
    from pathlib import Path
    from linkwork.outputs.staging import staged_output

    with staged_output(Path(sys.argv[1])) as stage:
        (stage / "path.csv").write_text("half", encoding="utf-8")
        os.kill(os.getpid(), getattr(signal, sys.argv[2]))
        time.sleep(30)
    """
)


@pytest.mark.parametrize(("name", "code"), [("SIGTERM", 128 + 15), ("SIGINT", 1)])
def test_a_signal_while_writing_removes_the_staging_folder(tmp_path: Path, name: str, code: int) -> None:
    out = tmp_path / "out"
    with staged_output(out) as stage:  # a previous complete result, written by linkwork
        (stage / "path.csv").write_text("complete", encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(
        [sys.executable, "-c", INTERRUPTED_WRITER, str(out), name], env=env, capture_output=True, timeout=60
    )
    assert done.returncode == code or (name == "SIGINT" and done.returncode != 0), done
    assert (out / "path.csv").read_text(encoding="utf-8") == "complete"
    assert sorted(p.name for p in out.iterdir()) == sorted(["path.csv", MANIFEST])
    assert not list(tmp_path.glob(".linkwork-*"))


def test_an_interrupted_demo_leaves_no_partial_output(tmp_path: Path) -> None:
    """Ctrl-C once the demo is writing into its staging folder: --out is not created (before, 20 files and no
    index.html were left) and the staging folder is removed."""
    out = tmp_path / "demo"
    script = Path(sys.executable).with_name("linkwork")
    if not script.exists():
        pytest.skip("the linkwork script is not installed")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "NO_COLOR": "1"}
    with subprocess.Popen(
        [str(script), "demo", "--no-plots", "--out", str(out)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    ) as proc:
        deadline = time.monotonic() + 120
        while not any((p / "hexagon").exists() for p in tmp_path.glob(".linkwork-*")):
            assert proc.poll() is None and time.monotonic() < deadline, "the demo never started writing"
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    assert proc.returncode != 0
    assert not out.exists()
    assert not list(tmp_path.glob(".linkwork-*"))
    assert b"Traceback" not in stderr


HELD_SIGNAL = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from linkwork.interrupts import install_safe_interrupt
    from linkwork.outputs.staging import staged_output

    # A stand-in for numba loading a kernel: code of a module in the numba package that receives the signal
    # part way and must run to its end.
    LOADER = (
        "def load(signum):\\n"
        "    import os, time\\n"
        "    os.kill(os.getpid(), signum)\\n"
        "    t = time.monotonic()\\n"
        "    while time.monotonic() - t < 0.2:\\n"
        "        pass\\n"
    )
    space = {"__name__": "numba.core.loader_stand_in"}
    exec(LOADER, space)
    install_safe_interrupt()
    name, out = sys.argv[1], Path(sys.argv[2])
    stage = "loading"
    try:
        with staged_output(out) as folder:
            (folder / "path.csv").write_text("half", encoding="utf-8")
            space["load"](2 if name == "SIGINT" else 15)
            stage = "loaded"
            time.sleep(10)
            stage = "never interrupted"
    except (KeyboardInterrupt, SystemExit) as exc:
        print(stage, "SystemExit" if isinstance(exc, SystemExit) else type(exc).__name__, flush=True)
    """
)


@pytest.mark.parametrize(("name", "raised"), [("SIGINT", "KeyboardInterrupt"), ("SIGTERM", "SystemExit")])
def test_a_signal_inside_the_compiler_is_held_until_it_returns(
    tmp_path: Path, name: str, raised: str
) -> None:
    """A signal that lands in numba's or llvmlite's code (a kernel loading from the cache: interrupted there,
    their C state is left half-built and the process crashed, one Ctrl-C of the demo in about thirty, leaving its
    staging folder) is delivered once that code has returned, and the staging folder is removed."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(
        [sys.executable, "-c", HELD_SIGNAL, name, str(tmp_path / "out")],
        env=env,
        capture_output=True,
        timeout=60,
    )
    assert done.stdout.decode().split() == ["loaded", raised], done
    assert not (tmp_path / "out").exists()
    assert not list(tmp_path.glob(".linkwork-*"))


def test_in_compiler_looks_at_every_calling_frame() -> None:
    space: dict[str, object] = {"__name__": "llvmlite.binding.stand_in", "sys": sys}
    exec("def inner(call):\n    return call()\n", space)
    inner = space["inner"]
    assert callable(inner)
    assert in_compiler(inner(lambda: sys._getframe()))  # the lambda's caller is llvmlite's
    assert not in_compiler(sys._getframe())
    assert not in_compiler(None)
