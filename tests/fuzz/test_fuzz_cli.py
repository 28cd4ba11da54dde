"""Properties of the command line over generated flags and built-in parameters (hypothesis, fixed seed): exit
code 0, 2 or 3; a failure is one ``error:`` line on stderr with no traceback or warning; --out unchanged on exit
2; nothing outside --out touched (checked by :func:`fuzzkit.run_cli`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fuzzkit import FUZZ, HOSTILE_TEXT, run_cli
from hypothesis import given
from hypothesis import strategies as st

from linkwork.io.spec import _import_builtins
from linkwork.linkages.registry import REGISTRY

_import_builtins()
#: Built-ins quick to build (the Bricard linkages search for their start assembly, seconds each).
QUICK = sorted(name for name in REGISTRY if not name.startswith("bricard"))

flag_values = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "1e400", "-5", "0", "1e12", "1e-300", "3", "90", "", "=", "A=1"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-(10**20), max_value=10**20).map(str),
    st.sampled_from(HOSTILE_TEXT),
)


@pytest.fixture
def home(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path_factory.mktemp("home")
    monkeypatch.chdir(folder)
    return folder


@FUZZ
@given(name=st.sampled_from(QUICK), data=st.data())
def test_show_with_generated_parameters(home: Path, name: str, data: st.DataObject) -> None:
    keys = [*REGISTRY[name].params, "zz", "[/]"]
    given_ = data.draw(st.lists(st.tuples(st.sampled_from(keys), flag_values), max_size=3))
    args = ["show", name]
    for key, value in given_:
        args += ["--set", f"{key}={value}"]
    run_cli(args, home=home)


@FUZZ
@given(flags=st.lists(st.tuples(st.sampled_from(["--max-step", "--max-steps", "--steps", "--until", "--drive",
                                                 "--couple", "--fixed"]), flag_values), max_size=3))  # fmt: skip
def test_trace_with_generated_flags(home: Path, flags: list[tuple[str, str]]) -> None:
    out = home / "out"
    args = ["trace", "bennett", "--no-plots", "--out", str(out)]
    budget = ["--max-steps", "40"]
    for flag, value in flags:
        args += [flag, value]
    run_cli([*args, *budget] if "--max-steps" not in dict(flags) else args, out=out, home=home)
