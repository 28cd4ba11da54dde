"""Every command the README and docs/ show runs as written.

The fenced ``bash`` and ``console`` blocks of README.md and docs/**/*.md are read; each command (a ``bash`` line,
or a ``console`` line after its ``$`` prompt) is run in one shared temporary folder that holds a copy
of the repository's ``examples/``, in the order the files list them, each distinct command once (so a later
command can use what an earlier one wrote, and the wing is synthesised once for every page that shows it). A block
is left out only when the line before its fence says why: ``<!-- docs-test: skip: REASON -->`` (installing the
package, for instance). Commands added to the docs later are picked up without touching this file. ``linkwork``
commands run in this process through typer's test runner (the shell would pay the start-up and kernel loading
once per command); anything else goes to the shell. After a README command, the property its comment claims is
checked on what it wrote (readme_claims.py: the flat hexagon's solids are one rod section thick, the coupler
curve closes, ...), and every README command has such a claim.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import traceback
from collections.abc import Callable
from pathlib import Path

import pytest
from readme_claims import CLAIMS

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SKIP = re.compile(r"<!--\s*docs-test:\s*skip:\s*(\S.*?)\s*-->")
FENCE = re.compile(r"^```(\w*)\s*$")
#: Commands that start Dask worker processes: run by the shell, as a user would (their sockets and processes are
#: not this test process's to keep).
OWN_PROCESS = {"robustness", "search", "sweep"}


def documented_commands(file: Path) -> list[str]:
    """The commands of ``file``'s bash and console blocks, in order (blocks marked to skip left out)."""
    commands: list[str] = []
    lines = file.read_text(encoding="utf-8").splitlines()
    inside, kind, skipped, pending = False, "", False, False
    for i, line in enumerate(lines):
        fence = FENCE.match(line.strip())
        if fence and not inside:
            inside, kind = True, fence.group(1)
            skipped = i > 0 and SKIP.search(lines[i - 1]) is not None
            continue
        if fence and inside:
            inside = False
            continue
        if not inside or skipped or kind not in ("bash", "console", "sh", "shell"):
            continue
        text = line.strip()
        if commands and pending:
            commands[-1] = (
                commands[-1][:-1].rstrip() + " " + _without_comment(text)
            )  # after a trailing backslash
            pending = commands[-1].endswith("\\")
            continue
        if kind == "console":
            if not text.startswith("$ "):
                continue  # output shown after a command
            text = text[2:]
        if not text or text.startswith("#"):
            continue
        commands.append(_without_comment(text))
        pending = commands[-1].endswith("\\")
    return commands


def _without_comment(text: str) -> str:
    """The command without its trailing ``# comment`` (a ``#`` inside quotes or inside a word stays)."""
    quote = ""
    for i, ch in enumerate(text):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or text[i - 1].isspace()):
            return text[:i].strip()
    return text.strip()


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str]]:
    """The shared folder the commands run in (with ``examples/``), and the commands already run there."""
    folder = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "examples", folder / "examples")
    return folder, {}


def test_the_parser_reads_commands_and_skips_what_it_should(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        "```bash\nlinkwork linkages   # the built-ins\n# a comment\n```\n"
        "<!-- docs-test: skip: installs the package -->\n```bash\npip install linkwork\n```\n"
        "```console\n$ linkwork show bennett > b.toml\noutput line\n```\n"
        "```bash\nlinkwork trace bennett \\\n    --steps 5   # continued\n```\n"
        "```toml\nname = 'x'\n```\n"
    )
    assert documented_commands(page) == [
        "linkwork linkages",
        "linkwork show bennett > b.toml",
        "linkwork trace bennett --steps 5",
    ]


@pytest.mark.slow
@pytest.mark.parametrize("doc", DOCS, ids=[str(d.relative_to(ROOT)) for d in DOCS])
def test_documented_commands_run(
    doc: Path, workspace: tuple[Path, dict[str, str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    folder, done = workspace
    monkeypatch.chdir(folder)
    for command in documented_commands(doc):
        key = re.sub(r"\s+", " ", command.replace(" -o ", " --out "))  # the same command spelt two ways
        if key in done:
            continue
        done[key] = doc.name
        code, errors, output = run_documented(command, folder)
        assert code == 0, f"{doc.name}: `{command}` exited {code}: {errors[-2000:]}"
        assert "Traceback" not in errors, f"{doc.name}: `{command}`: {errors[-2000:]}"
        if doc.name == "README.md":
            for check in claims_of(command):
                check(folder, output)


def claims_of(command: str) -> list[Callable[[Path, str], None]]:
    """The checks of what a README command claims to show (readme_claims.CLAIMS)."""
    return [check for pattern, check in CLAIMS.items() if re.search(pattern, command)]


def test_every_readme_command_has_its_claim_checked() -> None:
    """Each README command is checked against what it says it shows, and each claim names exactly one command
    (a claim whose command was edited away would otherwise pass unseen)."""
    commands = documented_commands(ROOT / "README.md")
    unchecked = [c for c in commands if not claims_of(c)]
    assert not unchecked, f"README commands with no claim in tests/docs/readme_claims.py: {unchecked}"
    for pattern in CLAIMS:
        matching = [c for c in commands if re.search(pattern, c)]
        assert len(matching) == 1, f"claim {pattern!r} matches {matching}"


def run_documented(command: str, folder: Path) -> tuple[int, str, str]:
    """Run one documented command in ``folder``: a plain ``linkwork ...`` (optionally ``> FILE``) in this process
    (the compiled kernels stay loaded, so the docs test stays affordable), anything else by the shell. Returns the
    exit code, standard error and standard output."""
    words = shlex.split(command)
    target = None
    if len(words) > 2 and words[-2] == ">":
        words, target = words[:-2], words[-1]
    in_process = len(words) > 1 and words[0] == "linkwork" and words[1] not in OWN_PROCESS
    if in_process and not set(words) & {"|", "&&", ";", ">", "<", "||"}:
        from typer.testing import CliRunner

        from linkwork.cli import app

        result = CliRunner().invoke(app, words[1:])
        if target is not None:
            (folder / target).write_text(result.stdout)
        errors = result.stderr + (
            "".join(traceback.format_exception(result.exc_info[1]))
            if result.exc_info and not isinstance(result.exc_info[1], SystemExit)
            else ""
        )
        return result.exit_code, errors, result.stdout
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    run = subprocess.run(
        command, shell=True, cwd=folder, env=env, capture_output=True, text=True, timeout=900
    )
    return run.returncode, run.stderr, run.stdout


def test_docs_refer_to_nothing_outside_the_repository() -> None:
    outside = re.compile(r"DESIGN\.md|/work/|\bseed 00\d\b|papers/[\w-]+\.md")
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        assert not outside.search(text), f"{doc.relative_to(ROOT)}: {outside.search(text).group(0)!r}"
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
            if re.match(r"[a-z]+:", target):
                continue  # a web address
            assert (doc.parent / target).resolve().exists(), f"{doc.relative_to(ROOT)}: broken link {target}"
