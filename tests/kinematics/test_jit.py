"""Compiled and plain-Python tracing kernels (linkwork.kinematics.jit): the same numbers either way, one choice per
trace, the plain ones while the cache is cold on the command line (a background compile for next time), a
foreground compile for library calls, and compile time kept out of a trace's reported seconds.

The reference for the plain-Python path is the compiled path (and the other way round): they run the same
statements, so a trace must agree point for point to 1e-12 rad, with the same branches and bifurcation points.
"""

from __future__ import annotations

import logging
import subprocess
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numba.core.registry import CPUDispatcher

import linkwork as lw
from linkwork.kernel_cache import CACHE
from linkwork.kinematics import jit, march, tracer
from linkwork.linkages.hedgepeth_rods import deployed_angles


def _trace_in(mode: str, monkeypatch: pytest.MonkeyPatch, mech: lw.Mechanism, **kwargs: object) -> lw.Trace:
    monkeypatch.setenv("LINKWORK_JIT", mode)
    return lw.trace(mech, **kwargs)  # type: ignore[arg-type]


def _assert_same(a: lw.Trace, b: lw.Trace) -> None:
    assert a.angles.shape == b.angles.shape
    np.testing.assert_allclose(a.angles, b.angles, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.sigma, b.sigma, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.branch, b.branch)
    assert [br.end_reason for br in a.branches] == [br.end_reason for br in b.branches]
    assert len(a.bifurcations) == len(b.bifurcations)
    for p, q in zip(a.bifurcations, b.bifurcations, strict=True):
        np.testing.assert_allclose(p.angles, q.angles, rtol=0, atol=1e-12)


def test_python_kernels_trace_the_hexagon_as_the_compiled_ones(monkeypatch: pytest.MonkeyPatch) -> None:
    hexagon = lw.load("hedgepeth-rods", n=6)
    until = ("A", deployed_angles(6)[0])
    _assert_same(
        _trace_in("python", monkeypatch, hexagon, until=until),
        _trace_in("compiled", monkeypatch, hexagon, until=until),
    )


def test_python_kernels_find_the_same_bifurcations(monkeypatch: pytest.MonkeyPatch) -> None:
    # Guest's frame: its first bifurcation points and the branches leaving them, with a small budget.
    frame = lw.load("guest-frame")
    kwargs = {"branches": True, "max_steps": 700}
    python = _trace_in("python", monkeypatch, frame, **kwargs)
    assert python.bifurcations, "the budget must reach a bifurcation point for this test to mean anything"
    _assert_same(python, _trace_in("compiled", monkeypatch, frame, **kwargs))


def test_the_python_twin_calls_no_compiled_code() -> None:
    twin = jit.python_backend()
    seen: set[int] = set()

    def walk(fn: types.FunctionType) -> None:
        if id(fn) in seen:
            return
        seen.add(id(fn))
        for name in fn.__code__.co_names:
            value = fn.__globals__.get(name)
            assert not isinstance(value, CPUDispatcher), f"{fn.__name__} calls compiled {name}"
            if isinstance(value, types.FunctionType) and value.__module__.startswith("linkwork"):
                walk(value)

    for name in jit.ENTRY_POINTS:
        walk(getattr(twin, name))
    assert len(seen) >= 8  # march, correct, evaluate, closure_jacobian, exp_unit_twist, log_rigid, ...
    assert not twin.compiled and jit.compiled_backend().compiled
    assert jit.compiled_backend().march is march.march


@pytest.fixture
def cold(monkeypatch: pytest.MonkeyPatch) -> list[list[str]]:
    """A cold cache (no marker, nothing loaded in this process), with background compiles recorded, not run."""
    started: list[list[str]] = []
    monkeypatch.setattr(CACHE, "ready", lambda group: False)
    monkeypatch.setitem(jit._state, "loaded", False)
    monkeypatch.setitem(jit._state, "spawned", False)
    monkeypatch.setattr(jit, "compile_under_way", lambda: False)
    monkeypatch.setattr(jit, "hold_lock", lambda: None)
    monkeypatch.setattr(
        subprocess, "run", lambda cmd, **kw: started.append([*cmd, kw["env"]["LINKWORK_JIT"]])
    )
    monkeypatch.setattr(tracer, "warm_up", lambda: time.sleep(0.3))  # a stand-in compile of a known length
    monkeypatch.setattr(jit, "_background", [])
    monkeypatch.setenv("LINKWORK_JIT", "auto")
    return started


def test_a_cold_command_line_run_traces_in_python_and_compiles_in_the_background(
    cold: list[list[str]], caplog: pytest.LogCaptureFixture
) -> None:
    jit.enable_background_compile(["python", "-c", "compile everything"])
    with caplog.at_level(logging.INFO, logger="linkwork.jit"):
        backend = jit.select_backend(warm_up=tracer.warm_up)
        again = jit.select_backend(warm_up=tracer.warm_up)  # a second trace starts no second compile
    assert backend is jit.python_backend() and again is backend
    assert cold == [[sys.executable, "-c", jit.LAUNCHER, "python", "-c", "compile everything", "compiled"]]
    assert "compiling kernels, first run only" in caplog.text


def test_a_cold_library_call_compiles_in_the_foreground_and_starts_no_process(
    cold: list[list[str]], caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.INFO, logger="linkwork.jit"):
        backend = jit.select_backend(warm_up=tracer.warm_up)
    assert backend is jit.compiled_backend()
    assert cold == []  # a notebook or a Dask worker never starts a detached process
    assert "compiling kernels, first run only" in caplog.text


def test_one_trace_runs_one_backend_chosen_once(
    cold: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    # The cache turns warm in the middle of the trace (a background compile finished): the trace keeps its twin.
    jit.enable_background_compile(["true"])
    chosen: list[jit.Backend] = []
    real = jit.select_backend

    def select(mode: str | None = None, warm_up: Callable[[], None] | None = None) -> jit.Backend:
        chosen.append(real(mode, warm_up))
        monkeypatch.setattr(CACHE, "ready", lambda group: True)
        return chosen[-1]

    monkeypatch.setattr(tracer, "select_backend", select)
    calls: list[str] = []
    twin = jit.python_backend()
    spy = jit.Backend(False, *(_counting(getattr(twin, name), name, calls) for name in jit.ENTRY_POINTS))
    monkeypatch.setitem(jit._BACKENDS, False, spy)
    compiled_calls: list[str] = []
    real_compiled = jit.compiled_backend()
    watched = jit.Backend(
        True, *(_counting(getattr(real_compiled, name), name, compiled_calls) for name in jit.ENTRY_POINTS)
    )
    monkeypatch.setitem(jit._BACKENDS, True, watched)
    tr = lw.trace(lw.load("four-bar"), branches=True, max_steps=300)
    assert len(chosen) == 1 and chosen[0] is spy
    assert {"march", "evaluate"} <= set(calls)  # the twin's kernels ran ...
    assert compiled_calls == []  # ... and the compiled ones never, though the cache turned warm
    assert tr.branches


def _counting(fn: Callable[..., object], name: str, calls: list[str]) -> Callable[..., object]:
    def call(*args: object, **kwargs: object) -> object:
        calls.append(name)
        return fn(*args, **kwargs)

    return call


def test_the_launcher_starts_a_detached_process_and_returns_at_once(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    child = f"import pathlib, time; time.sleep(0.5); pathlib.Path({str(marker)!r}).write_text('yes')"
    begin = time.perf_counter()
    subprocess.run([sys.executable, "-c", jit.LAUNCHER, sys.executable, "-c", child], check=True, timeout=30)
    assert not marker.exists()  # the launcher did not wait for its child
    for _ in range(200):  # the detached child finishes on its own (up to 20 s on a loaded machine)
        if marker.exists():
            break
        time.sleep(0.1)
    assert marker.read_text() == "yes", f"launched {time.perf_counter() - begin:.1f} s ago"


def test_compile_time_is_not_trace_time(cold: list[list[str]], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("LINKWORK_JIT", "compiled")
    begin = time.perf_counter()
    tr = lw.trace(lw.load("bennett"), until=("A", np.radians(70.0)))
    elapsed = time.perf_counter() - begin
    assert elapsed >= 0.3
    assert tr.stats.seconds <= elapsed - 0.3 + 1e-3


def test_an_unknown_mode_is_reported_and_auto_used(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setenv("LINKWORK_JIT", "fast")
    with caplog.at_level(logging.WARNING, logger="linkwork.jit"):
        assert jit.mode() == "auto"
    assert "LINKWORK_JIT=fast" in caplog.text


def test_the_normalised_ratio_is_the_same_with_the_python_jacobian(monkeypatch: pytest.MonkeyPatch) -> None:
    from linkwork.kinematics import normalization

    tr = lw.trace(lw.load("bennett"), until=("A", np.radians(70.0)))
    monkeypatch.setenv("LINKWORK_JIT", "compiled")
    compiled = normalization.condition_ratios(tr.mechanism, tr.angles, tr.rank)
    monkeypatch.setenv("LINKWORK_JIT", "python")
    plain = normalization.condition_ratios(tr.mechanism, tr.angles, tr.rank)
    np.testing.assert_allclose(plain, compiled, rtol=1e-12, atol=0.0)


def test_the_warm_up_traces_the_built_in_bennett_linkage() -> None:
    from linkwork.kinematics.chains import from_dh

    params = [{"theta": t, "d": 0.0, "a": np.sin(al), "alpha": al} for t, al in tracer.WARM_UP_DH]
    mech, _ = from_dh("Bennett linkage", params, joint_names=("A", "B", "C", "D"))
    builtin = lw.load("bennett")
    np.testing.assert_allclose(mech.offsets, builtin.offsets, rtol=0, atol=1e-15)
    np.testing.assert_allclose(mech.twists, builtin.twists, rtol=0, atol=1e-15)


def test_a_cold_command_line_run_computes_the_normalised_ratio_in_python_too(cold: list[list[str]]) -> None:
    # The ratio (report.json's max_condition) is a call of its own: on a cold command-line run it must not
    # compile its kernel in the foreground either.
    jit.enable_background_compile(["true"])
    assert jit.select_backend() is jit.python_backend()
    jit.disable_background_compile()
    assert (
        jit.select_backend() is jit.compiled_backend()
    )  # a library call: compiled (numba compiles on first call)
