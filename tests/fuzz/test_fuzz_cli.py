"""Properties of the command line over generated flags and built-in parameters (hypothesis, fixed seed): exit
code 0, 2 or 3; a failure is one ``error:`` line on stderr with no traceback or warning; --out unchanged on exit
2; nothing outside --out touched (checked by :func:`fuzzkit.run_cli`)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fuzzkit import EXAMPLES, FUZZ, HOSTILE_TEXT, run_cli
from hypothesis import given, settings
from hypothesis import strategies as st

from linkwork.io.spec import import_builtins
from linkwork.linkages.registry import REGISTRY

import_builtins()
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


SYNTH_EXAMPLES = max(3, EXAMPLES // 2)  # a synthesis takes about a second


@settings(parent=FUZZ, max_examples=SYNTH_EXAMPLES)
@given(names=st.lists(st.sampled_from(HOSTILE_TEXT), min_size=2, max_size=2),
       design=st.sampled_from(['"MC"', '"auto"\nsegments = 2', '"CM"', '"mx"', "3"]),
       extra=st.sampled_from(["", "merge_below = 179.9", "merge_below = nan", "seed = 4294967296", "starts = 0"]),
       html=st.booleans())  # fmt: skip
def test_synth_with_hostile_names_and_settings(
    home: Path, names: list[str], design: str, extra: str, html: bool
) -> None:
    import json

    import numpy as np

    from linkwork.io.profiles import save_profile

    folder = home / "problem"
    folder.mkdir(exist_ok=True)
    t = np.linspace(0.0, 1.0, 40)
    save_profile(folder / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(folder / "b.csv", np.column_stack([1.3 * t, 0.3 * t**2]))
    text = (
        f'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\nstarts = 1\ndesign = {design}\n'
        f"names = {json.dumps(names)}\n{extra}\n"
    )
    (folder / "problem.toml").write_text(text, encoding="utf-8")
    out = home / "out"
    args = ["synth", str(folder / "problem.toml"), "--out", str(out), "--no-plots"]
    run = run_cli([*args, "--html"] if html else args, out=out, home=home)
    if run.code == 0:
        for name in names:
            assert " ".join(name.split())[:20] in " ".join(run.stdout.split()) or len(name) > 100
