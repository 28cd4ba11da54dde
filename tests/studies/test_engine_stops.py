"""Dask runs end cleanly (issue 19 item 5): SIGINT and SIGTERM keep what was computed and mark it (exit 130, 143),
losing every worker keeps it too (exit 3), a scheduler that accepts connections and never answers is given up
after $LINKWORK_CONNECT_TIMEOUT seconds (exit 3), and no Dask traceback reaches the terminal.

The commands run as real processes (a signal must reach a real main thread), on 127.0.0.1 only."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

ROBUSTNESS = [
    "robustness", "bennett", "--until", "A=120", "--steps", "40", "--samples", "2000000",
    "--hinge-position-tol", "1e-3", "--hinge-direction-tol", "0.1", "--no-plots",
]  # fmt: skip


def linkwork(args: list[str], **env: str) -> subprocess.Popen[bytes]:
    script = Path(sys.executable).with_name("linkwork")
    if not script.exists():
        pytest.skip("the linkwork script is not installed")
    full = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "NO_COLOR": "1", **env}
    return subprocess.Popen(
        [str(script), *args], env=full, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True
    )


def wait_for_samples(proc: subprocess.Popen[bytes], folder: Path, timeout: float = 240.0) -> None:
    """Wait until the run has streamed its first chunk of samples into its staging folder (the file starts
    with a 4-byte header)."""
    deadline = time.monotonic() + timeout
    while not any(p.stat().st_size > 4 for p in folder.glob(".linkwork-*/samples.parquet")):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the study never started"
        time.sleep(0.2)
    time.sleep(1.0)  # a few chunks more


def check_partial(out: Path, err: bytes, reason: str | tuple[str, ...]) -> dict[str, object]:
    import pyarrow.parquet as pq

    text = err.decode()
    reasons = (reason,) if isinstance(reason, str) else reason
    assert "Traceback" not in text and len(text.strip().splitlines()) == 1, text[:3000]
    assert text.startswith(tuple(f"error: {r}" for r in reasons)), text
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["complete"] is False and summary["samples_asked"] == 2_000_000
    table = pq.read_table(out / "samples.parquet")
    assert 0 < summary["samples"] == table.num_rows < 2_000_000
    assert table["sample"].to_pylist() == list(range(table.num_rows))  # the first samples, in order
    assert f"{summary['samples']} of 2000000 samples" in text
    return summary


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_keeps_the_samples_computed_and_marks_them(tmp_path: Path, sig: int, code: int) -> None:
    out = tmp_path / "rb"
    proc = linkwork([*ROBUSTNESS, "--workers", "2", "-o", str(out)])
    wait_for_samples(proc, tmp_path)
    os.killpg(proc.pid, sig)  # the whole process group, as Ctrl-C in a terminal does
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    summary = check_partial(out, err, "interrupted (")
    assert summary["stopped"] == f"interrupted ({signal.Signals(sig).name})"
    assert not list(tmp_path.glob(".linkwork-*"))


@pytest.mark.slow
def test_a_signal_in_process_mode_keeps_the_samples_too(tmp_path: Path) -> None:
    out = tmp_path / "rb"
    proc = linkwork([*ROBUSTNESS, "--workers", "0", "-o", str(out)])
    wait_for_samples(proc, tmp_path)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    check_partial(out, err, "interrupted (SIGTERM)")


@pytest.mark.slow
def test_losing_every_worker_keeps_what_was_computed_and_exits_3(tmp_path: Path) -> None:
    out = tmp_path / "rb"
    proc = linkwork([*ROBUSTNESS, "--workers", "2", "-o", str(out)], LINKWORK_CONNECT_TIMEOUT="5")
    wait_for_samples(proc, tmp_path)
    children = subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True, text=True).stdout.split()
    for pid in children:  # the worker processes (each has threads), not multiprocessing's resource tracker
        if len(os.listdir(f"/proc/{pid}/task")) > 1:
            os.kill(int(pid), signal.SIGKILL)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 3, err
    check_partial(out, err, "lost every Dask worker")


@pytest.fixture
def silent_scheduler() -> Iterator[str]:
    """A TCP server on 127.0.0.1 that accepts every connection and never says a word."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(16)
    server.settimeout(0.2)
    held: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        while not stop.is_set():
            try:
                held.append(server.accept()[0])
            except OSError:
                continue

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    stop.set()
    thread.join(5)
    for conn in held:
        conn.close()
    server.close()


@pytest.mark.slow
@pytest.mark.parametrize("command", ["robustness", "sweep"])
def test_a_scheduler_that_never_answers_is_given_up_after_the_timeout(
    tmp_path: Path, silent_scheduler: str, command: str
) -> None:
    study = tmp_path / "s.toml"
    study.write_text('linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 5\n[grid]\nalpha1 = [30, 40]\n')
    args = [*ROBUSTNESS[:7], "400", *ROBUSTNESS[8:]] if command == "robustness" else ["sweep", str(study)]
    start = time.monotonic()
    proc = linkwork(
        [*args, "--scheduler", silent_scheduler, "-o", str(tmp_path / "o")], LINKWORK_CONNECT_TIMEOUT="2"
    )
    _, err = proc.communicate(timeout=120)
    assert time.monotonic() - start < 100  # seconds; before, over 10 minutes
    assert proc.returncode == 3, err
    text = err.decode()
    assert text.strip() == (
        f"error: the Dask scheduler at {silent_scheduler} accepted the connection but did not answer within 2 s "
        "(set LINKWORK_CONNECT_TIMEOUT to wait longer)"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("address", "fragment"),
    [("tcp://", '"tcp://"'), ("tcp://127.0.0.1:0", "port 1 to 65535"), ("udp://h:1", '"udp://h:1"')],
)
def test_a_malformed_scheduler_address_is_bad_input(tmp_path: Path, address: str, fragment: str) -> None:
    from typer.testing import CliRunner

    from linkwork.cli import app

    result = CliRunner().invoke(app, [*ROBUSTNESS, "--scheduler", address, "-o", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert f"--scheduler {fragment}" in result.stderr or fragment in result.stderr
    assert "expected an address like tcp://HOST:PORT" in result.stderr


def test_a_bad_connect_timeout_is_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from linkwork.errors import SpecError
    from linkwork.studies.engine import connect_timeout

    monkeypatch.setenv("LINKWORK_CONNECT_TIMEOUT", "nan")
    with pytest.raises(SpecError, match="LINKWORK_CONNECT_TIMEOUT='nan': expected a number of seconds"):
        connect_timeout()


def _chunk(shared: list[int], index: int) -> int:
    """A chunk that sends this process a signal when it is chunk ``shared[0]`` (as a user's Ctrl-C would)."""
    if index == shared[0]:
        os.kill(os.getpid(), shared[1])
    return index * index


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_the_engine_keeps_the_chunks_before_a_signal_and_says_why(sig: int, code: int) -> None:
    from linkwork.studies.engine import RunStatus, map_chunks

    status = RunStatus()
    before = signal.getsignal(sig)
    done = list(map_chunks(_chunk, [2, sig], [(i,) for i in range(6)], workers=0, status=status))
    assert done == [0, 1, 4]  # chunks 0, 1 and the one in hand when the signal came, in order
    assert (status.done, status.total, status.code) == (3, 6, code)
    assert status.stopped == f"interrupted ({signal.Signals(sig).name})" and not status.complete
    assert signal.getsignal(sig) == before  # the handlers are the caller's again


def test_without_a_status_a_signal_is_the_usual_interrupt() -> None:
    from linkwork.studies.engine import map_chunks

    with pytest.raises(KeyboardInterrupt):
        list(map_chunks(_chunk, [1, signal.SIGINT], [(i,) for i in range(4)], workers=0))


def _traced_chunk(shared: list[int], index: int) -> int:
    """A chunk that traces the four-bar round, sending this process a signal first when it is chunk
    ``shared[0]``: the points traced."""
    import linkwork as lw

    if index == shared[0]:
        os.kill(os.getpid(), shared[1])
    return len(lw.trace(lw.load("four-bar")).angles)


def test_a_chunk_in_hand_runs_whole() -> None:
    """The engine holds signals with the one hold of every command (interrupts.held_signals), and runs a chunk
    under interrupts.whole: the trace in the chunk the signal came in is not cut short (its points are those of
    a trace with no signal), and the run stops after it."""
    import linkwork as lw
    from linkwork.studies.engine import RunStatus, map_chunks

    points = len(lw.trace(lw.load("four-bar")).angles)
    status = RunStatus()
    done = list(
        map_chunks(_traced_chunk, [1, signal.SIGTERM], [(i,) for i in range(4)], workers=0, status=status)
    )
    assert done == [points, points] and status.stopped == "interrupted (SIGTERM)" and status.code == 143


def test_the_engine_shares_a_hold_its_caller_made() -> None:
    """Inside a caller's hold the engine's hold is the same one: the signal is the caller's to see after the run
    (as the CLI's), and the run still stops after the chunk in hand."""
    from linkwork.interrupts import held_signals, requested
    from linkwork.studies.engine import RunStatus, map_chunks

    before = signal.getsignal(signal.SIGINT)
    status = RunStatus()
    with held_signals() as hold:
        done = list(
            map_chunks(_chunk, [1, signal.SIGINT], [(i,) for i in range(4)], workers=0, status=status)
        )
        assert requested() == signal.SIGINT  # still held: the caller decides what to do with it
    assert done == [0, 1] and status.code == 130 and hold.signum == signal.SIGINT
    assert signal.getsignal(signal.SIGINT) == before


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.mark.slow
def test_losing_the_scheduler_keeps_what_was_computed_and_exits_3(tmp_path: Path) -> None:
    """A scheduler and two workers on 127.0.0.1 (dask's own commands); the scheduler is killed mid-run."""
    dask = Path(sys.executable).with_name("dask")
    if not dask.exists():
        pytest.skip("the dask command is not installed")
    address = f"tcp://127.0.0.1:{_free_port()}"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    port = address.rsplit(":", 1)[1]
    scheduler = subprocess.Popen(
        [str(dask), "scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard"], env=env, **quiet
    )
    workers = subprocess.Popen(
        [str(dask), "worker", address, "--nthreads", "1", "--nworkers", "2", "--no-dashboard", "--host",
         "127.0.0.1", "--death-timeout", "20"],
        env=env, start_new_session=True, **quiet,
    )  # fmt: skip
    try:
        out = tmp_path / "rb"
        proc = linkwork([*ROBUSTNESS, "--scheduler", address, "-o", str(out)], LINKWORK_CONNECT_TIMEOUT="20")
        wait_for_samples(proc, tmp_path)
        scheduler.kill()
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 3, err
        # The scheduler's death reaches the client either as such or as every worker gone with it (they lose
        # their scheduler too): which comes first is a race; both keep what was computed, exit 3.
        check_partial(out, err, ("lost the Dask scheduler", "lost every Dask worker"))
    finally:
        scheduler.kill()
        os.killpg(workers.pid, signal.SIGKILL)
        scheduler.wait(30)
        workers.wait(30)
