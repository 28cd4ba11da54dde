"""What every command shares: turning linkwork errors into one clear line and exit code 2 or 3, quietly.

A command decorated with :func:`friendly_errors` runs with numpy's floating-point warnings and Python's
``RuntimeWarning``\\ s silenced, and any other warning shown as one ``note:`` line, so that the one ``error:``
line is the only error on stderr when it fails and no source line is ever printed.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from functools import wraps
from typing import TYPE_CHECKING, Any, ParamSpec, TypeVar

import typer
from rich.console import Console
from rich.text import Text

from linkwork.errors import LinkworkError, RequestNotMetError
from linkwork.interrupts import EXIT_SIGINT, Interrupted, Terminated, exit_code, stop_text
from linkwork.io.toml_reader import escape_line, show
from linkwork.limits import PLAIN_INTEGER, Limit, plain_number
from linkwork.messages import show_path
from linkwork.progress import Progress

try:  # typer >= 0.20 carries its own copy of click, whose exceptions are these
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - older typer uses click itself
    from click import exceptions as click_exceptions  # type: ignore[no-redef]

if TYPE_CHECKING:
    from linkwork.kinematics.mechanism import Mechanism

err_console = Console(stderr=True)

MAX_MESSAGE_CHARS = 2000
"""An error line longer than this is cut (a hostile value can be megabytes long)."""

MAX_INTEGER_DIGITS = 40
"""The most characters of a whole number read as one (every bound is far below; Python's ``int`` refuses more
than 4300 digits with a traceback, and click words its refusal of a long one without the flag's bounds)."""

P = ParamSpec("P")
R = TypeVar("R")


def fail(message: str, code: int = 2) -> typer.Exit:
    """Print ``error: message`` on one line to stderr and return the exit to raise (code 2: bad input; 3: the
    request could not be met). The message is printed as text, never as rich markup, with line breaks and
    other control characters escaped."""
    message = escape_line(message)
    if len(message) > MAX_MESSAGE_CHARS:
        message = message[: MAX_MESSAGE_CHARS - 3] + "..."
    line = Text("error:", style="bold red")
    line.append(" " + message)
    err_console.print(line, highlight=False, soft_wrap=True)
    return typer.Exit(code=code)


def warning_note(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """Show a warning met while a command runs (one of matplotlib's, a deprecation) as one ``note:`` line on
    stderr, like the kernel announcements: never Python's two lines with a source file and its code."""
    text = escape_line(str(message))
    if len(text) > MAX_MESSAGE_CHARS:
        text = text[: MAX_MESSAGE_CHARS - 3] + "..."
    err_console.print(Text(f"note: {text}"), highlight=False, soft_wrap=True)


def friendly_errors(func: Callable[P, R]) -> Callable[P, R]:
    """Decorate a command so that a :class:`LinkworkError` becomes one line on stderr and exit code 2, or 3 for a
    :class:`RequestNotMetError`; numeric warnings are silenced while it runs."""

    @wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        import numpy as np

        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore", RuntimeWarning)
                warnings.showwarning = warning_note  # restored by catch_warnings
                return func(*args, **kwargs)
        except RequestNotMetError as exc:
            raise fail(str(exc), code=3) from None
        except LinkworkError as exc:
            raise fail(str(exc)) from None
        except RecursionError:
            raise fail("the input is nested too deeply to be processed") from None
        except OSError as exc:  # the file system refused, outside the readers and the writer's own checks
            message, code = os_error_line(exc)
            raise fail(message, code=code) from None
        except MemoryError:
            raise fail("ran out of memory; the request is too large for this machine", code=3) from None
        except (
            KeyboardInterrupt
        ):  # Ctrl-C where no signal is held (a study's run and a trace keep their results)
            raise fail("interrupted (SIGINT)", code=EXIT_SIGINT) from None
        except Terminated as exc:  # SIGTERM while files were written: the staging is gone, say why
            raise fail(stop_text(exc.signum), code=exit_code(exc.signum)) from None
        except Interrupted as exc:  # SIGTERM where none is held, or a second signal while the first was held
            text = f"interrupted twice ({exc}); stopped at once" if exc.again else f"interrupted ({exc})"
            raise fail(text, code=exit_code(exc.signum)) from None

    return wrapper


_PATH_EXPECTED = {
    errno.ENAMETOOLONG: "expected a shorter path (a name of at most 255 bytes)",
    errno.ENOENT: "expected an existing file or folder",
    errno.ENOTDIR: "expected a path through folders, not through a file",
    errno.EISDIR: "expected a file, not a folder",
    errno.ELOOP: "expected a path without a loop of symbolic links",
    errno.EACCES: "expected a place linkwork may read and write",
    errno.EPERM: "expected a place linkwork may read and write",
    errno.EROFS: "expected a place on a writable file system",
}
"""What a path the user gave should have been, by the ``errno`` that refused it: bad input, exit 2."""


def os_error_line(exc: OSError) -> tuple[str, int]:
    """The one error line and exit code of an ``OSError`` that reached a command: a path the user gave that the
    file system refuses (a name too long, not found, a file on the way) is bad input (exit 2, saying what was
    expected); anything else (a full disk, an I/O error) is a request that could not be met (exit 3)."""
    where = f"{show_path(exc.filename)}: " if exc.filename else ""
    reason = exc.strerror or str(exc)
    expected = _PATH_EXPECTED.get(exc.errno) if exc.errno is not None else None
    if expected is not None:
        return f"{where}{reason}; {expected}", 2
    return f"{where}{reason}", 3


def parse_assignments(items: list[str] | None, flag: str) -> dict[str, Any]:
    """Parse ``KEY=VALUE`` pairs of a repeated flag; values become int, float or str (never evaluated). A key
    given twice is refused."""
    out: dict[str, Any] = {}
    for item in items or []:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise fail(f"{flag} {show(item)}: expected KEY=VALUE")
        value: Any = raw  # text, unless it is a number as a person types one (limits.PLAIN_NUMBER)
        if PLAIN_INTEGER.fullmatch(
            raw
        ):  # kept as text when longer than any bound (int() of 4300 digits raises)
            value = int(raw) if len(raw) <= MAX_INTEGER_DIGITS else raw
        elif (number := plain_number(raw)) is not None:
            value = number
        if key.strip() in out:  # the last would win silently: refused, as a repeated --until is
            raise fail(f"{flag} {show(key.strip())} given twice ({show(item)}); expected each key once")
        out[key.strip()] = value
    return out


def check_word(flag: str, value: str, words: Sequence[str]) -> None:
    """Refuse a flag's value that is not one of ``words`` (the few words the flag takes), with one ``error:`` line
    naming the flag, the value and the words, as a file's key is refused (``expected one of "a", "b", got "x"``)."""
    if value not in words:
        quoted = ", ".join(f'"{word}"' for word in words)
        raise fail(f"{flag}: expected one of {quoted}, got {show(value)}")


def check_range(
    flag: str, value: float, low: float, high: float, what: str, *, open_low: bool = False
) -> None:
    """Refuse a flag's value outside ``[low, high]`` (``(low, high]`` with ``open_low``) or not finite, with a
    message stating the limit."""
    inside = (low < value if open_low else low <= value) and value <= high
    if not inside:  # also catches NaN
        sign = "<" if open_low else "<="
        raise fail(f"{flag} {show(value)}: expected {what}, {low:g} {sign} {flag} <= {high:g}")


def numeric_params(command: Any) -> Iterator[tuple[str, Any, Any]]:
    """``(command path, command, parameter)`` of every int or float parameter of every (sub)command of the
    click ``command`` (the typer app as built), whatever module declares it."""
    commands = getattr(command, "commands", None)
    if commands is not None:
        for name, sub in commands.items():
            for path, owner, param in numeric_params(sub):
                yield f"{name} {path}".strip(), owner, param
        return
    for param in getattr(command, "params", []):
        if _number_type(param) is not None:
            yield "", command, param


def _number_type(param: Any) -> type | None:
    """``int`` or ``float`` for a parameter holding one number (or a list of them), else ``None``."""
    descriptor = getattr(param, "type_descriptor", None)
    annotation = getattr(descriptor, "annotation", None)
    if annotation is None:  # a plain click parameter
        name = getattr(getattr(param, "type", None), "name", "")
        return {"integer": int, "float": float}.get(name)
    if annotation in (int, list[int]):
        return int
    if annotation in (float, list[float]):
        return float
    return None


def check_flags(app_command: Any) -> None:
    """Attach the bounds of :data:`linkwork.cli.options.FLAG_LIMITS` to every numeric flag of the built command
    line, so each value is checked (type, finite, range) as it is parsed, before any command starts its work.

    A numeric flag without declared bounds still has to be a finite number; the fuzz suite fails on it so that
    its bounds get declared. A refused value is one ``error:`` line naming the flag and its bounds (exit 2).
    """
    from linkwork.cli.options import FLAG_LIMITS

    for _, _, param in numeric_params(app_command):
        if getattr(param, "_linkwork_checked", False):
            continue
        flag = max(param.opts, key=len) if param.opts else param.name
        limit = FLAG_LIMITS.get(flag)
        param.callback = _checked_callback(flag, limit, param.callback)
        param._linkwork_checked = True


def _checked_callback(flag: str, limit: Limit | None, then: Callable[..., Any] | None) -> Callable[..., Any]:
    """A click parameter callback refusing a value outside ``limit`` (or any non-finite number)."""

    def check(ctx: Any, param: Any, value: Any) -> Any:
        for item in value if isinstance(value, list | tuple) else [value]:
            if item is None:
                continue
            if limit is not None and limit.broken(item):
                raise click_exceptions.UsageError(f"{flag} {show(item)}: expected {limit.expected(flag)}")
            if limit is None and not math.isfinite(float(item)):
                raise click_exceptions.UsageError(f"{flag} {show(item)}: expected a finite number")
        return then(ctx, param, value) if then is not None else value

    return check


def option_misuse(group: Any, args: Sequence[str]) -> str | None:
    """What is wrong with the options of the command ``args`` call in ``group`` (the built app), as the words of
    an ``error:`` line, or ``None``: an option that takes one value given twice (``--until A=80 --until A=90``,
    ``-o a --out b``: click keeps the last silently, so a slip in a long command line would run with a value the
    user did not mean; repeatable options such as ``--set`` and on/off flags are not counted), or any option given
    an empty value (``-o "$OUT"`` with ``OUT`` unset: click reads ``--out ''`` as the working folder)."""
    command, rest = group, list(args)
    while getattr(command, "commands", None) is not None:
        if not rest or rest[0].startswith("-") or rest[0] not in command.commands:
            return None  # a root option, or a command click refuses itself
        command, rest = command.commands[rest[0]], rest[1:]
    takes_value: dict[str, Any] = {}
    for param in getattr(command, "params", []):
        if param.param_type_name == "option" and not param.is_flag and not param.count:
            takes_value.update(dict.fromkeys(param.opts, param))
    seen: set[str] = set()
    i = 0
    while i < len(rest):
        token = rest[i]
        if token == "--":
            break
        long_form = token.startswith("--")
        name = token.partition("=")[0] if long_form else token[:2]
        param = takes_value.get(name) if token.startswith("-") else None
        if param is None:
            i += 1
            continue
        flag = str(max(param.opts, key=len))
        if not param.multiple:
            if param.name in seen:
                return f"{flag} given twice; expected it once (it takes one value)"
            seen.add(param.name)
        attached = "=" in token if long_form else len(token) > 2
        if attached:
            value: str | None = token.partition("=")[2] if long_form else token[2:]
        else:
            value = rest[i + 1] if i + 1 < len(rest) else None
        if value is not None and not value.strip():
            return f"{flag} {show(value)}: expected a value (an empty one is not the working folder or a default)"
        if value is not None and (typed := _typed_number_misuse(param, flag, value)) is not None:
            return typed
        i += 1 if attached else 2
    return None


def _typed_number_misuse(param: Any, flag: str, value: str) -> str | None:
    """What is wrong with the text ``value`` of a numeric flag, or ``None``: one rule for a number a person types
    (:data:`linkwork.limits.PLAIN_NUMBER`, :data:`linkwork.limits.PLAIN_INTEGER`), the rule of ``--set``,
    ``--until`` and profile files. click's own conversion takes ``1_0`` for 10, ``3.0`` for a whole 3 and
    spaces around the digits, and words its refusal of ``1e3`` without the value or the bounds."""
    from linkwork.cli.options import FLAG_LIMITS
    from linkwork.limits import PLAIN_NUMBER

    kind = _number_type(param)
    if kind is None:
        return None
    pattern = PLAIN_INTEGER if kind is int else PLAIN_NUMBER
    if pattern.fullmatch(value) and not (kind is int and len(value) > MAX_INTEGER_DIGITS):
        return None
    limit = FLAG_LIMITS.get(flag)
    if limit is not None:
        expected = limit.expected(flag)
    else:
        expected = "a whole number" if kind is int else "a number"
    digits = "ASCII digits" + ("" if kind is int else ", a decimal point and an exponent")
    return f"{flag} {show(value)}: expected {expected} (written with {digits})"


ENVIRONMENT_CHECKS: dict[str, str] = {
    "NUMBA_NUM_THREADS": "a whole number of threads >= 1",
    "MPLBACKEND": "a matplotlib backend such as agg",
}
"""The environment variables linkwork's dependencies read as the command starts, with what each must be: numba
refuses ``NUMBA_NUM_THREADS=0`` with a traceback when the kernels load and prints one of its own with a source
line for ``x``; matplotlib refuses an unknown ``MPLBACKEND`` with a traceback when the first figure is drawn."""


def environment_misuse(environ: Mapping[str, str] | None = None) -> str | None:
    """What is wrong with the environment a command runs in, as the words of an ``error:`` line (bad input,
    exit 2, before any work), or ``None``: a variable of :data:`ENVIRONMENT_CHECKS` set to something its reader
    refuses with a traceback. The values are checked without importing numba, and matplotlib only when
    ``MPLBACKEND`` is set."""
    env = os.environ if environ is None else environ
    threads = env.get("NUMBA_NUM_THREADS")
    if environ is None:  # set aside when linkwork was imported (numba reads it as it loads)
        from linkwork.kernel_cache import REFUSED_ENVIRONMENT

        threads = REFUSED_ENVIRONMENT.get("NUMBA_NUM_THREADS", threads)
    if threads is not None and not (PLAIN_INTEGER.fullmatch(threads.strip()) and int(threads) >= 1):
        return f"environment variable NUMBA_NUM_THREADS={show(threads)}: expected {ENVIRONMENT_CHECKS['NUMBA_NUM_THREADS']}"
    backend = env.get("MPLBACKEND")
    if backend:
        try:
            from matplotlib.rcsetup import validate_backend  # matplotlib reads MPLBACKEND as it loads

            validate_backend(backend)
        except ImportError:  # no plotting extra: nothing will read it
            return None
        except ValueError:
            return f"environment variable MPLBACKEND={show(backend)}: expected {ENVIRONMENT_CHECKS['MPLBACKEND']}"
    return None


def check_workers(workers: int | None) -> None:
    """Refuse a ``--workers`` outside ``0 ..`` the machine's cores (0 runs a study in this process); the flag
    is checked as it is parsed, this repeats it for a caller that passes the value itself."""
    from linkwork.limits import WORKERS

    if workers is not None and WORKERS.broken(workers):
        raise fail(f"--workers {show(workers)}: expected {WORKERS.expected('--workers')}")


@contextlib.contextmanager
def progress_bar(label: str, total: int | None, *, fraction: bool = False) -> Iterator[Progress]:
    """A rich progress bar on a terminal (nothing otherwise), handed out as a ``progress(done, total)`` callback.

    The bar counts ``total`` units labelled ``label``, or, with ``total=None``, as many as the callback's ``total``
    says as the work goes on. The callback's ``done`` is shown as it is, or, with
    ``fraction``, as the fraction ``done / total`` of the bar (a computation that counts other units, such as
    chunks of samples).
    """
    from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn
    from rich.progress import Progress as Bar

    from linkwork.outputs.staging import console

    with Bar(
        TextColumn(label),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as bar:
        task = bar.add_task("", total=total)

        def update(done: int, of: int | None) -> None:
            if total is None:  # the computation says how much there is as it goes
                bar.update(task, completed=done, total=None if of is None else max(of, done))
                return
            if fraction:
                done = min(total, round(total * done / max(of or 1, 1)))
            bar.update(task, completed=done)

        yield update


def parse_until(text: str | None) -> tuple[str, float] | None:
    """``--until JOINT=VALUE`` (VALUE in degrees, or a length for a prismatic joint), or None without the flag."""
    return parse_joint_value(text, "--until", "A=87.0067")


def parse_joint_value(text: str | None, flag: str, example: str) -> tuple[str, float] | None:
    """A ``flag JOINT=VALUE`` (VALUE in degrees, or a length for a prismatic joint), or None without the flag;
    anything else is one line naming the flag, with ``example``."""
    if text is None:
        return None
    name, sep, raw = text.partition("=")
    number = plain_number(raw)  # ASCII digits: Python's float would take 1_0 and other scripts' digits
    value = float("nan") if number is None else number
    if not sep or not name.strip() or not math.isfinite(value):
        raise fail(
            f"{flag} {show(text)}: expected JOINT=VALUE with VALUE in degrees (a length for a prismatic joint), "
            f"e.g. {example}"
        )
    return name.strip(), value


def joint_named(mech: Mechanism, name: str, flag: str) -> int:
    """The index of the joint a flag names, or one line naming the flag and the joints there are."""
    if not mech.has_joint(name):
        raise fail(f"{flag} {show(name)}: unknown joint; expected one of {', '.join(mech.joint_names)}")
    return mech.index(name)


def until_in_api_units(
    mech: Mechanism, target: tuple[str, float] | None, flag: str = "--until"
) -> tuple[str, float] | None:
    """A parsed ``--until`` (or ``flag``) in the API's units: degrees become radians for a revolute joint; a
    length stays. An unknown joint is one line naming the flag."""
    if target is None:
        return None
    name, value = target
    revolute = mech.joint_types[joint_named(mech, name, flag)] == "R"
    return name, math.radians(value) if revolute else float(value)


def parse_couple(items: list[str] | None) -> list[list[str]]:
    """``--couple A=C=E`` (repeatable): groups of joints forced equal."""
    groups = []
    for item in items or []:
        names = [x.strip() for x in item.split("=")]
        if len(names) < 2 or not all(names):
            raise fail(f"--couple {show(item)}: expected joints joined by '=', e.g. A=C=E")
        if len(set(names)) < len(names):  # A=A couples nothing: a slip, not a request
            raise fail(f"--couple {show(item)}: names a joint twice; expected distinct joints, e.g. A=C=E")
        groups.append(names)
    return groups
