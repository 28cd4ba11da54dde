"""The one reader (:mod:`linkwork.io.readback`): every built-in's trace folder reads back to the traced values
exactly (17 significant digits written), and every damaged file derived from the file schemas (empty, truncated
at any byte, binary, not UTF-8, short rows, non-numeric or non-finite cells, missing keys, wrong types) is one
:class:`SpecError` line naming the file, never another exception."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import linkwork as lw
from linkwork.errors import SpecError
from linkwork.export.trace_folder import read_trace_folder
from linkwork.io.readback import SCHEMAS, read_chain, read_mechanization, read_report
from linkwork.io.schema import CsvSchema, JsonSchema, TomlSchema
from linkwork.linkages.registry import REGISTRY
from linkwork.outputs.trace import write_trace_outputs

FAST = settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, lw.Trace]]:
    """A short trace folder of every built-in (joint values as they were traced)."""
    root = tmp_path_factory.mktemp("builtins")
    out = {}
    for name in REGISTRY:
        mech = lw.load(name)
        trace = lw.trace(mech, max_steps=12)
        write_trace_outputs(trace, root / name, plots=False)
        out[name] = (root / name, trace)
    return out


def test_schemas_are_listed_by_file_name() -> None:
    """SCHEMAS names every file linkwork reads back, each with a reader."""
    assert {
        "path.csv",
        "points.csv",
        "report.json",
        "drawing.json",
        "chain.json",
        "mechanization.json",
    } <= set(SCHEMAS)
    assert {"mechanism.toml", "problem.toml", "study.toml"} <= set(SCHEMAS)
    for name, schema in SCHEMAS.items():
        assert schema.file == name
        assert isinstance(schema, CsvSchema | JsonSchema | TomlSchema)


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_every_builtin_reads_back_exactly(folders: dict[str, tuple[Path, lw.Trace]], name: str) -> None:
    folder, trace = folders[name]
    back = read_trace_folder(folder)
    assert back.angles.shape == trace.angles.shape
    np.testing.assert_allclose(back.angles, trace.angles, rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(back.branch, trace.branch)
    read_report(folder / "report.json")
    SCHEMAS["points.csv"].read(folder / "points.csv")  # type: ignore[call-arg]


def damage(text: bytes, kind: str, at: float) -> bytes:
    """A damaged copy of a file's bytes; ``at`` in [0, 1) picks where."""
    k = int(at * len(text))
    lines = text.split(b"\n")
    i = 1 + int(at * max(len(lines) - 2, 1))
    if kind == "empty":
        return b""
    if kind == "truncate":
        return text[:k]
    if kind == "binary":
        return text[:k] + bytes([0xFF, 0xFE, 0x00, 0x81]) + text[k:]
    if kind == "nul":
        return text[:k] + b"\x00" + text[k:]
    if kind == "short-row":
        lines[i] = b",".join(lines[i].split(b",")[:-1])
        return b"\n".join(lines)
    if kind in ("nan", "inf", "word", "empty-cell"):
        cells = lines[i].split(b",")
        j = int(at * 997) % max(len(cells), 1)
        cells[j] = {"nan": b"nan", "inf": b"-inf", "word": b"x1", "empty-cell": b""}[kind]
        lines[i] = b",".join(cells)
        return b"\n".join(lines)
    if kind == "header":
        lines[0] = lines[0].replace(b"step", b"stp").replace(b"branch", b"brunch")
        return b"\n".join(lines)
    raise AssertionError(kind)


def json_damage(value: object, kind: str, at: float) -> bytes:
    """A JSON file whose structure is damaged: a key removed, a value of the wrong type, a non-finite number."""
    if not isinstance(value, dict) or not value:
        return b"[]"
    keys = sorted(value)
    key = keys[int(at * len(keys)) % len(keys)]
    bad = dict(value)
    if kind == "missing":
        del bad[key]
    elif kind == "wrong-type":
        bad[key] = [{"x": None}] if not isinstance(value[key], list) else "text"
    elif kind == "nonfinite":
        return json.dumps(bad).replace(json.dumps(key) + ":", json.dumps(key) + ': NaN, "_":', 1).encode()
    return json.dumps(bad).encode()


def assert_refused_or_read(read, file: Path, must: bool = False) -> None:  # type: ignore[no-untyped-def]
    """``read()`` either succeeds (``must`` False: the damage left a valid file) or raises one SpecError line
    naming ``file``; any other exception fails the test."""
    try:
        read()
    except SpecError as exc:
        message = str(exc)
        assert "\n" not in message
        assert str(file) in message, message
    else:
        assert not must, f"{file}: damaged file read without complaint"


@given(
    builtin=st.sampled_from(sorted(REGISTRY)),
    file=st.sampled_from(["path.csv", "drawing.json", "mechanism.toml"]),
    kind=st.sampled_from(
        ["empty", "truncate", "binary", "nul", "short-row", "nan", "inf", "word", "empty-cell", "header"]
    ),
    at=st.floats(0.0, 0.999),
)
@FAST
def test_damaged_trace_folder_is_one_line(
    folders: dict[str, tuple[Path, lw.Trace]], tmp_path_factory: pytest.TempPathFactory, builtin: str, file: str,
    kind: str, at: float,
) -> None:  # fmt: skip
    source, _ = folders[builtin]
    folder = tmp_path_factory.mktemp("damaged")
    shutil.copytree(source, folder, dirs_exist_ok=True)
    target = folder / file
    target.write_bytes(damage(target.read_bytes(), kind, at))
    must = kind in ("empty", "binary", "nul") or (
        file == "path.csv" and kind in ("header", "nan", "inf", "word")
    )
    assert_refused_or_read(lambda: read_trace_folder(folder), target, must=must)


@given(
    name=st.sampled_from(["report.json", "drawing.json"]),
    builtin=st.sampled_from(sorted(REGISTRY)),
    kind=st.sampled_from(["missing", "wrong-type", "nonfinite", "truncate", "binary"]),
    at=st.floats(0.0, 0.999),
)
@FAST
def test_damaged_json_is_one_line(
    folders: dict[str, tuple[Path, lw.Trace]], tmp_path_factory: pytest.TempPathFactory, name: str, builtin: str,
    kind: str, at: float,
) -> None:  # fmt: skip
    source, _ = folders[builtin]
    folder = tmp_path_factory.mktemp("json")
    shutil.copytree(source, folder, dirs_exist_ok=True)
    target = folder / name
    text = target.read_bytes()
    if kind in ("truncate", "binary"):
        target.write_bytes(damage(text, kind, at))
    else:
        target.write_bytes(json_damage(json.loads(text), kind, at))
    schema = SCHEMAS[name]
    assert_refused_or_read(lambda: schema.read(target), target)  # type: ignore[call-arg]
    assert_refused_or_read(lambda: read_trace_folder(folder), folder)


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("", "is empty"),
        ('{"design": "MC"', "invalid JSON"),
        ('{"design": "MC", "joined": {"e_max": NaN}}', "NaN"),
        ('{"design": "MC", "joined": {}}', "joined.e_max"),
        ('{"design": 3, "joined": {"e_max": 1}}', "design"),
        ('{"design": "MC", "joined": {"e_max": 1}, "units": "furlong"}', "units"),
    ],
)
def test_chain_json_damage_names_the_key(tmp_path: Path, text: str, where: str) -> None:
    file = tmp_path / "chain.json"
    file.write_text(text)
    with pytest.raises(SpecError, match=where) as info:
        read_chain(file)
    assert str(file) in str(info.value)


def test_mechanization_json_needs_its_keys(tmp_path: Path) -> None:
    file = tmp_path / "mechanization.json"
    file.write_text('{"dof": 1, "drive": "A", "profiles": [{"e_max": "x"}]}')
    with pytest.raises(SpecError, match=r"profiles\[0\]\.e_max: expected a finite number"):
        read_mechanization(file)
