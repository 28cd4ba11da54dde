"""The one writer (:mod:`linkwork.io.writer`): ownership (a user's file is never replaced or deleted), a run
replacing its own earlier results as a whole (no stale viewer), no writing through symbolic links, staging cleaned
on every exit path, errors naming the user's path (a full disk by ``ulimit -f`` and by a patched ENOSPC), and
non-finite numbers refused. Checked through the commands and by a hypothesis state machine of runs, parts,
single files and a user's own files."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, rule
from typer.testing import CliRunner, Result

from linkwork.cli import app
from linkwork.errors import RequestNotMetError, SpecError
from linkwork.io.writer import MANIFEST, Manifest, require_finite, staged_output, write_file

runner = CliRunner()


def invoke(*args: object) -> Result:
    result = runner.invoke(app, [str(a) for a in args])
    assert "Traceback" not in result.stdout + result.stderr
    return result


def leftovers(folder: Path) -> list[Path]:
    """Staging folders or temporary files left behind."""
    return [p for p in folder.rglob(".linkwork-*") if p.name != MANIFEST]


@pytest.fixture(scope="module")
def trace_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("trace") / "four-bar"
    assert (
        invoke("trace", "four-bar", "--drive", "A", "--until", "A=90", "--no-plots", "-o", out).exit_code == 0
    )
    return out


EXPORTS = [("stl", "mine.stl"), ("stl", "mine.3mf"), ("mjcf", "mine.xml"), ("dxf", "mine.dxf")]


@pytest.mark.parametrize(("kind", "name"), EXPORTS)
def test_a_users_file_is_never_overwritten_by_an_export(
    tmp_path: Path, trace_dir: Path, kind: str, name: str
) -> None:
    mine = tmp_path / name
    mine.write_bytes(b"the user's own file")
    result = invoke("export", kind, trace_dir, "-o", mine)
    assert result.exit_code == 2
    assert str(mine) in result.stderr and "not written by linkwork" in result.stderr
    assert mine.read_bytes() == b"the user's own file"
    # what linkwork wrote it may replace: remove the user's file, export twice
    mine.unlink()
    assert invoke("export", kind, trace_dir, "-o", mine).exit_code == 0
    first = mine.stat().st_mtime_ns
    assert invoke("export", kind, trace_dir, "-o", mine).exit_code == 0
    assert mine.stat().st_mtime_ns >= first
    assert name in Manifest.read(tmp_path).files
    assert not leftovers(tmp_path)


@pytest.mark.parametrize(("kind", "name"), EXPORTS)
def test_an_export_never_writes_through_a_link(tmp_path: Path, trace_dir: Path, kind: str, name: str) -> None:
    user = tmp_path / "user.txt"
    user.write_text("keep")
    link = tmp_path / name
    link.symlink_to(user)
    result = invoke("export", kind, trace_dir, "-o", link)
    assert result.exit_code == 2 and "symbolic link" in result.stderr
    assert user.read_text() == "keep" and link.is_symlink()


def test_a_rerun_replaces_its_own_results_as_a_whole(tmp_path: Path) -> None:
    """`trace bennett --html -o st` then `trace four-bar -o st`: no Bennett viewer (or figure) stays behind."""
    st_ = tmp_path / "st"
    assert invoke("trace", "bennett", "--html", "--no-plots", "-o", st_, "--max-steps", "30").exit_code == 0
    assert (st_ / "viewer.html").is_file()
    (st_ / "notes.txt").write_text("the user's notes")
    assert invoke("trace", "four-bar", "--no-plots", "-o", st_, "--max-steps", "30").exit_code == 0
    names = {p.name for p in st_.iterdir()}
    assert names == {
        "path.csv",
        "report.json",
        "points.csv",
        "mechanism.toml",
        "drawing.json",
        "notes.txt",
        MANIFEST,
    }
    assert (st_ / "notes.txt").read_text() == "the user's notes"
    assert Manifest.read(st_).owned() == names - {"notes.txt", MANIFEST}


def test_a_link_in_an_output_folder_is_never_followed(tmp_path: Path) -> None:
    out = tmp_path / "st"
    assert invoke("trace", "bennett", "--no-plots", "-o", out, "--max-steps", "20").exit_code == 0
    user = tmp_path / "user.csv"
    user.write_text("user data")
    (out / "path.csv").unlink()
    (out / "path.csv").symlink_to(user)  # listed in the manifest, but now a link to the user's file
    result = invoke("trace", "bennett", "--no-plots", "-o", out, "--max-steps", "20")
    assert result.exit_code == 2 and "symbolic link" in result.stderr
    assert user.read_text() == "user data"
    # a link planted where linkwork writes its manifest is replaced, never written through (and a manifest that
    # is a link lists nothing: the entries beside it are then not linkwork's)
    fresh = tmp_path / "fresh"
    fresh.mkdir()
    for planted in (MANIFEST + ".part", MANIFEST):
        (fresh / planted).symlink_to(user)
    assert invoke("trace", "bennett", "--no-plots", "-o", fresh, "--max-steps", "20").exit_code == 0
    assert user.read_text() == "user data"
    assert not (fresh / MANIFEST).is_symlink() and "path.csv" in Manifest.read(fresh).owned()
    (out / "path.csv").unlink()
    (out / MANIFEST).unlink()
    (out / MANIFEST).symlink_to(user)
    assert invoke("trace", "bennett", "--no-plots", "-o", out, "--max-steps", "20").exit_code == 2
    assert user.read_text() == "user data"


def test_a_stale_entry_replaced_by_a_link_is_left_alone(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with staged_output(out) as stage:
        (stage / "a").write_text("1")
        (stage / "b").write_text("1")
    user = tmp_path / "user"
    user.write_text("u")
    (out / "b").unlink()
    (out / "b").symlink_to(user)
    with staged_output(out) as stage:
        (stage / "a").write_text("2")
    assert (out / "b").is_symlink() and user.read_text() == "u"
    assert Manifest.read(out).owned() == {"a"}


class OutputFolder(RuleBasedStateMachine):
    """Runs, parts of runs, single files and the user's own files in one folder: the user's files are never
    touched; after every step, the folder's linkwork entries are exactly the last run's, its parts' and the single
    files'."""

    def __init__(self) -> None:
        super().__init__()
        import tempfile

        self.root = Path(tempfile.mkdtemp(prefix="rw-machine-"))
        self.out = self.root / "out"
        self.user: dict[str, str] = {}
        self.expected: dict[str, dict[str, str]] = {}  # part -> {name: content}
        self.files: dict[str, str] = {}
        self.counter = 0

    def teardown(self) -> None:
        import shutil

        shutil.rmtree(self.root, ignore_errors=True)

    names = st.sampled_from(["path.csv", "report.json", "viewer.html", "m.toml", "x.stl", "notes.txt", "sub"])

    def owner(self, name: str) -> str | None:
        if name in self.user:
            return "user"
        if name in self.files or any(name in v for v in self.expected.values()):
            return "linkwork"
        return None

    @rule(names=st.sets(names, max_size=4), part=st.sampled_from(["run", "mechanize"]), fail=st.booleans())
    def run(self, names: set[str], part: str, fail: bool) -> None:
        self.counter += 1
        content = f"run {self.counter}"
        blocked = [n for n in names if self.owner(n) == "user"]
        try:
            with staged_output(self.out, part=part) as stage:
                for n in sorted(names):
                    if n == "sub":
                        (stage / n).mkdir()
                        (stage / n / "inner").write_text(content)
                    else:
                        (stage / n).write_text(content)
                if fail:
                    raise RuntimeError("a writer failed")
        except RuntimeError:
            return
        except SpecError:
            assert blocked
            return
        assert not blocked
        if part == "run":
            self.expected = {}
        for v in self.expected.values():
            for n in names:
                v.pop(n, None)
        self.expected[part] = dict.fromkeys(names, content)
        for n in names:
            self.files.pop(n, None)

    @rule(name=st.sampled_from(["x.stl", "path.csv", "notes.txt", "y.dxf"]))
    def single(self, name: str) -> None:
        self.counter += 1
        content = f"file {self.counter}"
        self.out.mkdir(exist_ok=True)
        in_run = any(name in v for v in self.expected.values())  # an entry of a run's results
        try:
            write_file(self.out / name, lambda tmp: tmp.write_text(content))
        except SpecError:
            # a user's file, a folder, or an entry of a run's results (which other commands read back)
            assert self.owner(name) == "user" or (self.out / name).is_dir() or in_run
            return
        assert self.owner(name) != "user" and not in_run
        self.files[name] = content

    @rule(name=names)
    def user_writes(self, name: str) -> None:
        if self.owner(name) is None and name != "sub":
            self.out.mkdir(exist_ok=True)
            (self.out / name).write_text("user")
            self.user[name] = "user"

    @invariant()
    def consistent(self) -> None:
        if not self.out.exists():
            return
        for name, text in self.user.items():
            assert (self.out / name).read_text() == text
        want = {n: c for v in self.expected.values() for n, c in v.items()} | self.files
        have = {p.name for p in self.out.iterdir()} - {MANIFEST} - set(self.user)
        assert have == set(want)
        for n, c in want.items():
            f = self.out / n / "inner" if n == "sub" else self.out / n
            assert f.read_text() == c
        assert not leftovers(self.root)


TestOutputFolder = OutputFolder.TestCase
TestOutputFolder.settings = settings(
    max_examples=60,
    stateful_step_count=12,
    deadline=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)


def test_a_full_disk_names_the_users_folder_not_the_staging(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "results"
    with staged_output(out) as stage:
        (stage / "path.csv").write_text("complete")

    with pytest.raises(RequestNotMetError) as info, staged_output(out) as stage:
        raise OSError(errno.ENOSPC, "No space left on device", str(stage / "path.csv"))
    message = str(info.value)
    assert str(out) in message and ".linkwork-" not in message and "No space left" in message
    assert (out / "path.csv").read_text() == "complete"
    assert not leftovers(tmp_path)

    with pytest.raises(RequestNotMetError) as info:
        write_file(
            tmp_path / "x.stl", lambda tmp: (_ for _ in ()).throw(OSError(errno.ENOSPC, "full", str(tmp)))
        )
    assert str(tmp_path / "x.stl") in str(info.value) and ".linkwork-" not in str(info.value)
    assert not (tmp_path / "x.stl").exists() and not leftovers(tmp_path)


def test_a_file_size_limit_through_the_command_line(tmp_path: Path) -> None:
    """``ulimit -f`` (RLIMIT_FSIZE) in a subprocess: exit 3, one line naming --out, nothing left behind."""
    resource = pytest.importorskip("resource")
    script = Path(sys.executable).with_name("linkwork")
    if not script.exists():
        pytest.skip("the linkwork script is not installed")
    out = tmp_path / "big"

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "NO_COLOR": "1"}
    done = subprocess.run(
        [str(script), "trace", "four-bar", "--no-plots", "-o", str(out)],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=limit,
    )
    assert done.returncode == 3, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and str(out) in lines[0] and ".linkwork-" not in lines[0], done.stderr
    assert not out.exists() and not leftovers(tmp_path)


SINGLE_FILE_INTERRUPTED = textwrap.dedent(
    """
    import os, signal, sys, time
    from pathlib import Path
    from linkwork.io.writer import write_file

    def write(tmp):
        tmp.write_text("half")
        os.kill(os.getpid(), getattr(signal, sys.argv[2]))
        time.sleep(30)

    write_file(Path(sys.argv[1]), write)
    """
)


@pytest.mark.parametrize("name", ["SIGTERM", "SIGINT"])
def test_a_signal_while_writing_a_file_leaves_no_temporary(tmp_path: Path, name: str) -> None:
    target = tmp_path / "mine.stl"
    write_file(target, lambda tmp: tmp.write_text("complete"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(
        [sys.executable, "-c", SINGLE_FILE_INTERRUPTED, str(target), name],
        env=env,
        capture_output=True,
        timeout=60,
    )
    assert done.returncode != 0
    if name == "SIGTERM":
        assert done.returncode == 128 + signal.SIGTERM
    assert target.read_text() == "complete" and not leftovers(tmp_path)


@pytest.mark.parametrize("scale", ["inf", "-1", "0", "nan"])
def test_a_non_finite_or_non_positive_scale_is_refused(tmp_path: Path, trace_dir: Path, scale: str) -> None:
    result = invoke("export", "stl", trace_dir, "-o", tmp_path / "x.stl", "--scale", scale)
    assert result.exit_code == 2 and "--scale" in result.stderr
    assert not (tmp_path / "x.stl").exists()


def test_a_huge_scale_writes_only_finite_numbers(tmp_path: Path, trace_dir: Path) -> None:
    """``--scale 1e9`` (the largest the flag checker accepts): the coordinates are finite, and so are the facet
    normals (computed without overflow); ``1e300`` is refused before anything is written."""
    out = tmp_path / "x.stl"
    assert invoke("export", "stl", trace_dir, "-o", out, "--scale", "1e9").exit_code == 0
    numbers = [float(w) for line in out.read_text().splitlines() for w in line.split()[2 if "normal" in line else 1 :]
               if line.strip().startswith(("vertex", "facet"))]  # fmt: skip
    assert numbers and all(abs(x) < float("inf") for x in numbers)
    for huge in ("1e300", "1e308"):
        result = invoke("export", "stl", trace_dir, "-o", tmp_path / "y.stl", "--scale", huge)
        assert result.exit_code == 2 and "--scale" in result.stderr and not (tmp_path / "y.stl").exists()


def test_require_finite_names_what() -> None:
    assert require_finite([1.0, 2.0], "x").tolist() == [1.0, 2.0]
    for bad in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(SpecError, match="the thing: expected finite numbers"):
            require_finite([[0.0, bad]], "the thing")


DAMAGE = {
    "empty path.csv": ("path.csv", lambda b: b""),
    "truncated path.csv": ("path.csv", lambda b: b[: len(b) // 3]),
    "binary path.csv": ("path.csv", lambda b: b"\x89PNG\r\n\x1a\n\x00\xff" + b[:100]),
    "short-row path.csv": ("path.csv", lambda b: b + b"0,1,2\n"),
    "nan in path.csv": ("path.csv", lambda b: b.replace(b"\n0,1,", b"\n0,1,nan,", 1)),
    "truncated drawing.json": ("drawing.json", lambda b: b[: len(b) // 2]),
    "truncated report.json": ("report.json", lambda b: b[: len(b) // 2]),
    "mistyped report.json": ("report.json", lambda b: b'{"joints": "A", "drive": 3}'),
}


@pytest.mark.parametrize("case", sorted(DAMAGE))
@pytest.mark.parametrize("kind", ["stl", "mjcf", "dxf"])
def test_a_damaged_trace_folder_is_one_line_exit_2(
    tmp_path: Path, trace_dir: Path, case: str, kind: str
) -> None:
    """The campaign's cases: ``export`` on a damaged trace folder is one line naming the file, exit 2."""
    import shutil

    folder = tmp_path / "trace"
    shutil.copytree(trace_dir, folder)
    name, damage = DAMAGE[case]
    (folder / name).write_bytes(damage((folder / name).read_bytes()))
    result = invoke("export", kind, folder, "-o", tmp_path / f"x.{'xml' if kind == 'mjcf' else kind}")
    reads = {"stl": {"path.csv", "drawing.json"}, "mjcf": {"drawing.json", "report.json"},
             "dxf": {"path.csv", "drawing.json"}}  # fmt: skip
    if name not in reads[kind]:
        assert result.exit_code == 0  # that command does not read that file
        return
    assert result.exit_code == 2, result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and str(folder / name) in result.stderr.replace("\n", "")


def test_a_folder_that_cannot_be_written_names_the_users_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The staging cannot be made (a read-only parent; patched, since the tests may run as root): exit 2 naming
    --out; a refused write inside the staging: the same, never the staging's name."""
    import tempfile

    out = tmp_path / "results"

    def refuse(*args: object, **kwargs: object) -> str:
        raise PermissionError(errno.EACCES, "Permission denied", str(tmp_path))

    with monkeypatch.context() as m:
        m.setattr(tempfile, "mkdtemp", refuse)
        with pytest.raises(SpecError) as info, staged_output(out):
            pass
    assert str(out) in str(info.value) and "Permission denied" in str(info.value)
    with pytest.raises(SpecError) as info, staged_output(out) as stage:
        raise PermissionError(errno.EACCES, "Permission denied", str(stage / "viewer.html"))
    assert str(out) in str(info.value) and ".linkwork-" not in str(info.value)
    assert not out.exists() and not leftovers(tmp_path)
    # a file the command reads on the way (not in the staging) keeps its own error
    with pytest.raises(FileNotFoundError), staged_output(out):
        (tmp_path / "missing.toml").read_text()
