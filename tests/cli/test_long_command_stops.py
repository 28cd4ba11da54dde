"""What ``synth``, ``mechanize`` and ``search`` keep when SIGTERM or Ctrl-C stops them (as ``trace`` does, see
test_trace_stops.py): each runs as a real process on an input that runs for many seconds, gets a real signal once
it has made progress (its progress bar on a terminal, or its records on disk), and must

* exit 143 / 130 with exactly one line on stderr saying what was kept (no traceback);
* leave its output folder whole (every file parses, the manifest lists them, no staging folder left), its report
  saying ``"complete": false`` and why it ``"stopped"``;
* keep results that are real: the kept chain is what evaluating its design vector afresh gives, the kept
  mechanism is what an uninterrupted search finding as many designs gives, the kept candidates' rows are what
  evaluating them afresh gives.

When nothing had been found yet, nothing is written (one line, 143 / 130).
"""

from __future__ import annotations

import json
import os
import re
import select
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest
from processes import linkwork_command, process_env
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.data import example
from linkwork.outputs.staging import MANIFEST

ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
TIMEOUT = 240.0
"""Seconds a step of a test may take on a loaded machine before it fails (generous: nothing waits for it)."""


class Running:
    """A ``linkwork`` command run as a process, its standard output on a pseudo-terminal (so that its progress
    bar is drawn, and read here), its standard error on a pipe."""

    def __init__(self, args: list[str]) -> None:
        import pty

        command = linkwork_command(args)
        env = process_env(TERM="xterm", COLUMNS="160")
        master, slave = pty.openpty()
        self.proc = subprocess.Popen(
            command, env=env, stdin=subprocess.DEVNULL, stdout=slave, stderr=subprocess.PIPE
        )
        os.close(slave)
        self.master = master
        self.output = b""
        self.lock = threading.Lock()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        """Drain the terminal until the process closes it (a full terminal would block the process)."""
        while True:
            ready, _, _ = select.select([self.master], [], [], 0.2)
            if not ready:
                if self.proc.poll() is not None:
                    return
                continue
            try:
                data = os.read(self.master, 65536)
            except OSError:  # the process ended and closed the terminal
                return
            if not data:
                return
            with self.lock:
                self.output += data

    def counted(self, label: str) -> int:
        """The largest count ``N`` of ``label ... N/`` the progress bar has shown so far (0: none)."""
        with self.lock:
            text = ANSI.sub("", self.output.decode(errors="replace"))
        counts = [int(n) for n in re.findall(rf"{label}[^\r\n0-9]*(\d+)/", text)]
        return max(counts, default=0)

    def wait_for(self, ready: object, what: str) -> None:
        """Wait until ``ready()`` is true, the process still running."""
        deadline = time.monotonic() + TIMEOUT
        while not ready():  # type: ignore[operator]
            assert self.proc.poll() is None, f"the command ended before {what}: {self.finish()}"
            assert time.monotonic() < deadline, f"never {what}"
            time.sleep(0.05)

    def stop(self, sig: int) -> tuple[int, str]:
        """Send ``sig``; the exit code and standard error once the process has ended."""
        assert self.proc.poll() is None, "the command ended before the signal: make its input longer"
        self.proc.send_signal(sig)
        return self.finish()

    def finish(self) -> tuple[int, str]:
        assert self.proc.stderr is not None
        try:
            code = self.proc.wait(timeout=TIMEOUT)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
        err = self.proc.stderr.read().decode(errors="replace")
        self.proc.stderr.close()
        self.reader.join(5)
        os.close(self.master)
        return code, err


def one_line(err: str) -> str:
    """The one line on stderr (a kernel announcement ``note:`` aside), which is an ``error:`` line."""
    assert "Traceback" not in err, err
    lines = [line for line in ANSI.sub("", err).strip().splitlines() if not line.startswith("note:")]
    assert len(lines) == 1, lines
    assert lines[0].startswith("error: interrupted ("), lines[0]
    return lines[0]


def assert_whole_folder(out: Path, names: set[str], hidden: tuple[str, ...] = ()) -> None:
    """``names`` are in ``out`` and in its manifest; no staging folder beside or inside it (``hidden``: the
    command's own hidden entries, a search's records)."""
    manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    owned = set().union(*manifest["parts"].values())
    assert names <= owned and names <= {p.name for p in out.iterdir()}
    assert not list(out.parent.glob(".linkwork-*")), "a staging folder was left behind"
    assert sorted(p.name for p in out.glob(".linkwork-*")) == sorted([MANIFEST, *hidden])


SIGNALS = pytest.mark.parametrize(
    ("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)], ids=["SIGTERM", "SIGINT"]
)


# ------------------------------------------------------------------------------------------------ synth
def long_synthesis(folder: Path) -> Path:
    """The bundled wing's profiles with every design vector of 8 segments (255) and 200 starts each: about 20 s
    of search with the compiled kernels (0.4 s for the bundled 5 segments and 4 starts)."""
    shutil.copytree(example("wing", "problem.toml").parent, folder)
    text = (folder / "problem.toml").read_text(encoding="utf-8")
    text = text.replace("segments = 5", "segments = 8").replace("starts = 4", "starts = 200")
    assert "segments = 8" in text and "starts = 200" in text
    (folder / "long.toml").write_text(text, encoding="utf-8")
    return folder / "long.toml"


def test_a_signal_during_the_design_search_writes_the_best_chain_so_far(tmp_path: Path) -> None:
    from linkwork.io.problem import load_problem
    from linkwork.synthesis.search import evaluate_design
    from linkwork.synthesis.segment_matrix import design_vectors

    problem_file = long_synthesis(tmp_path / "wing")
    out = tmp_path / "out"
    run = Running(["synth", str(problem_file), "--no-plots", "-o", str(out)])
    run.wait_for(lambda: run.counted("synthesising") >= 2 * 201, "searched two design vectors")
    code, err = run.stop(signal.SIGTERM)
    assert code == 143, err
    line = one_line(err)
    chain = json.loads((out / "chain.json").read_text(encoding="utf-8"))
    assert chain["complete"] is False and chain["stopped"] == "interrupted (SIGTERM)"
    search = chain["search"]
    tried, left = search["designs_tried"], search["not_searched"]
    assert tried >= 2 and left >= 1 and tried + left == 255
    assert line == (
        f"error: interrupted (SIGTERM): the best chain found so far (design {chain['design']}, joined E_max "
        f"{chain['joined']['e_max']:.4g}; {tried} of 255 design vectors searched) is written to {out}/ "
        '(chain.json says "complete": false)'
    )
    assert_whole_folder(out, {"chain.json", "target_profiles.csv", "outline.svg", "outline.dxf", "problem"})
    # the designs searched are the first ones of the search's order, the chosen one the best of those joined
    problem = load_problem(problem_file)
    pieces = [t["pieces"] for t in chain["profiles"]]
    assert {d["design"] for d in search["designs"]} == set(design_vectors(8, pieces)[:tried])
    joined = [d["joined_e_max"] for d in search["designs"] if d["joined_e_max"] is not None]
    assert joined and chain["joined"]["e_max"] == min(joined)
    # and it is what evaluating that design vector afresh gives (segment matrix, joined error)
    fresh = evaluate_design(problem, chain["design"])
    assert fresh.segmentation.segment_matrix.tolist() == chain["segment_matrix"]
    assert fresh.joined_e_max == pytest.approx(chain["joined"]["e_max"], rel=1e-12, abs=0.0)
    # a stopped chain is not mechanized from: the seeded synthesis run again would give another
    refused = CliRunner().invoke(app, ["mechanize", str(out)])
    assert refused.exit_code == 2 and '"complete": false' in refused.stderr


def test_a_signal_before_any_design_is_joined_writes_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The signal comes (a real SIGTERM, to this process) as the search starts: no design vector is searched,
    nothing is written, one line and 143."""
    import importlib

    synthesize_module = importlib.import_module(
        "linkwork.synthesis.synthesize"
    )  # the package's name is a function
    real = synthesize_module.target_profiles

    def signalled(*args, **kwargs):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGTERM)  # held: the search stops before its first design vector
        return real(*args, **kwargs)

    monkeypatch.setattr(synthesize_module, "target_profiles", signalled)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["synth", "wing", "--no-plots", "-o", str(out)])
    assert result.exit_code == 143, result.output
    assert one_line(result.stderr) == (
        f"error: interrupted (SIGTERM): no design vector had been joined yet; nothing is written to {out}/"
    )
    assert not out.exists() and not list(tmp_path.glob(".linkwork-*"))


# ------------------------------------------------------------------------------------------------ mechanize
MECHANIZE_FLAGS = ["--attempts", "100", "--designs", "20", "--no-plots"]
"""A search that goes on for about 25 designs traced after the first one passes (6 s with compiled kernels)."""


def mechanization(args: list[str]) -> dict[str, object]:
    """mechanization.json of ``linkwork mechanize ARGS`` run here to its end."""
    out = Path(args[0])
    result = CliRunner().invoke(app, ["mechanize", *args])
    assert result.exit_code == 0, result.output
    report: dict[str, object] = json.loads((out / "mechanization.json").read_text(encoding="utf-8"))
    assert report["complete"] is True and report["stopped"] is None
    return report


@SIGNALS
def test_a_signal_during_the_mechanization_writes_the_best_design_so_far(
    tmp_path: Path, sig: int, code: int
) -> None:
    chain = tmp_path / "chain"
    synth = CliRunner().invoke(
        app, ["synth", "wing/mechanize.toml", "--no-mechanize", "--no-plots", "-o", str(chain)]
    )
    assert synth.exit_code == 0, synth.output
    # the designs traced up to the first that passes: those of a search asking for one design
    first = mechanization([str(shutil.copytree(chain, tmp_path / "first")), "--designs", "1", "--no-plots"])
    first_pass = first["verification"]["attempts"]  # type: ignore[index]

    out = shutil.copytree(chain, tmp_path / "out")
    run = Running(["mechanize", str(out), *MECHANIZE_FLAGS])
    run.wait_for(lambda: run.counted("mechanizing") >= first_pass, "a design passed")
    returned, err = run.stop(sig)
    name = signal.Signals(sig).name
    assert returned == code, err
    line = one_line(err)
    kept = json.loads((out / "mechanization.json").read_text(encoding="utf-8"))
    assert kept["complete"] is False and kept["stopped"] == f"interrupted ({name})"
    designs, traced = len(kept["designs"]), kept["verification"]["attempts"]
    assert 1 <= designs < 20 and traced >= first_pass
    assert line == (
        f"error: interrupted ({name}): the best of the {designs} design(s) that passed verification so far "
        f'({traced} traced) is written to {out}/ (mechanization.json says "complete": false)'
    )
    assert_whole_folder(out, {"chain.json", "mechanism.toml", "mechanization.json"})
    import tomllib

    spec = tomllib.loads((out / "mechanism.toml").read_text(encoding="utf-8"))
    assert spec  # a linkage spec `linkwork trace` reads
    # the kept designs are those an uninterrupted search asking for as many designs finds, ranked the same
    whole = mechanization(
        [
            str(shutil.copytree(chain, tmp_path / "whole")),
            "--attempts",
            "100",
            "--designs",
            str(designs),
            "--no-plots",
        ]
    )
    for key in ("complete", "stopped", "seconds", "verification"):  # the search's own account differs
        kept.pop(key)
        whole.pop(key)
    assert kept == whole


# ------------------------------------------------------------------------------------------------ search
def long_search(folder: Path) -> Path:
    """Every face choice of Guest's cuts at four widths: 256 rect-frame members (a minute or more here)."""
    faces = json.dumps(["".join(f) for f in __import__("itertools").product("io", repeat=6)])
    file = folder / "study.toml"
    file.write_text(
        'name = "frames"\nlinkage = "rect-frame"\n[trace]\nmax_steps = 800\n[grid]\n'
        f'width = [0.4, 0.6, 0.8, 1.0]\ncuts = ["EW"]\nfaces = {faces}\n[criteria]\nmobility = 1\n',
        encoding="utf-8",
    )
    return file


def records(out: Path) -> int:
    """Candidates the search has recorded so far."""
    from linkwork.outputs.search import RECORDS

    try:
        return max(0, len((out / RECORDS).read_text(encoding="utf-8").splitlines()) - 1)
    except FileNotFoundError:
        return 0


@SIGNALS
def test_a_signal_during_a_search_writes_the_candidates_evaluated(
    tmp_path: Path, sig: int, code: int
) -> None:
    import csv

    import pyarrow.parquet as pq

    from linkwork.outputs.search import write_search_outputs
    from linkwork.studies.search import evaluate, load_search

    study_file = long_search(tmp_path)
    out = tmp_path / "out"
    run = Running(["search", str(study_file), "--workers", "0", "-o", str(out)])
    run.wait_for(lambda: records(out) >= 3, "evaluated three candidates")
    returned, err = run.stop(sig)
    name = signal.Signals(sig).name
    assert returned == code, err
    line = one_line(err)
    summary = json.loads((out / "search.json").read_text(encoding="utf-8"))
    assert summary["complete"] is False and summary["stopped"] == f"interrupted ({name})"
    n = summary["candidates"]
    assert 3 <= n < 256 and summary["candidates_asked"] == 256 and n == records(out)
    assert line == (
        f"error: interrupted ({name}): {n} of 256 candidate(s) evaluated are written to {out}/ (search.json says "
        '"complete": false; no gallery); run the same command again to continue'
    )
    assert_whole_folder(
        out, {"candidates.csv", "candidates.parquet", "ranked.csv", "search.json"}, (".linkwork-search",)
    )
    assert not (out / "gallery.html").exists() and not (out / "viewers").exists()
    with (out / "candidates.csv").open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["index"]) for r in rows] == list(range(n))  # in this process: the first ones, in grid order
    assert pq.read_table(out / "candidates.parquet").num_rows == n
    # every kept row is what evaluating that candidate afresh gives (no record read back)
    search = load_search(study_file)
    points = search.study.points()
    fresh = [{"index": i, **evaluate(search, points[i]).row} for i in range(n)]
    again = tmp_path / "fresh"
    write_search_outputs(search, fresh, again, stopped=f"interrupted ({name})")
    for file in ("candidates.csv", "ranked.csv", "search.json"):
        assert (out / file).read_text(encoding="utf-8") == (again / file).read_text(encoding="utf-8"), file
