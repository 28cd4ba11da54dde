"""The kernel cache (linkwork.kernel_cache): keyed to every kernel module's source, so that editing a kernel that
another file's kernel calls can never leave the caller running stale machine code; and the marker that says which
kernels are compiled.

The stale-code test runs real numba caches in subprocesses on a two-module toy package: ``outer`` (in b.py) calls
``inner`` (in a.py); a.py is edited. numba's own cache (the control) keeps returning the old result, because it
checks the caller's file only; the keyed cache returns the new one.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import linkwork
from linkwork import kernel_cache
from linkwork.kernel_cache import CACHE, KERNEL_MODULES, KernelCache

TOY_CACHE = """
from pathlib import Path
from linkwork.kernel_cache import KernelCache
ROOT = Path(__file__).resolve().parent
CACHE = KernelCache(ROOT, ("a.py", "b.py"), "toy", parent=ROOT / "keyed")
"""
TOY_A = """
import numba
from cache import CACHE

@CACHE.kernel()
def inner(x):
    return x + {step}

@numba.njit(cache=True)
def plain_inner(x):
    return x + {step}
"""
TOY_B = """
import numba
from a import inner, plain_inner
from cache import CACHE

@CACHE.kernel()
def outer(x):
    return 2.0 * inner(x)

@numba.njit(cache=True)
def plain_outer(x):
    return 2.0 * plain_inner(x)
"""
RUN = "import sys; sys.path.insert(0, sys.argv[1]); from b import outer, plain_outer; print(outer(1.0), plain_outer(1.0))"


def _run(toy: Path) -> list[float]:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run(
        [sys.executable, "-c", RUN, str(toy)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    return [float(x) for x in out.stdout.split()]


def test_editing_a_called_kernel_never_runs_stale_compiled_code(tmp_path: Path) -> None:
    toy = tmp_path / "toy"
    toy.mkdir()
    (toy / "cache.py").write_text(TOY_CACHE)
    (toy / "a.py").write_text(TOY_A.format(step="1.0"))
    (toy / "b.py").write_text(TOY_B)
    assert _run(toy) == [4.0, 4.0]  # compiled and cached
    assert _run(toy) == [4.0, 4.0]  # loaded from both caches
    (toy / "a.py").write_text(TOY_A.format(step="2.0"))  # edit the callee only
    stamp = (toy / "a.py").stat().st_mtime + 10.0
    os.utime(toy / "a.py", (stamp, stamp))
    keyed, plain = _run(toy)
    assert keyed == 6.0  # recompiled: a.py's new source changed the key, so a new, empty cache directory
    assert (
        plain == 4.0
    )  # the control: numba's own cache still runs the old inner (the trap this module closes)
    assert len(list((toy / "keyed").glob("kernels-*"))) == 2


def test_the_key_follows_every_kernel_source_and_nothing_else(tmp_path: Path) -> None:
    package = Path(linkwork.__file__).resolve().parent
    copy = tmp_path / "linkwork"
    for name in KERNEL_MODULES:
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(package / name, copy / name)
    same = KernelCache(copy, KERNEL_MODULES, linkwork.__version__, parent=tmp_path / "c")
    assert same.key == CACHE.key  # the same sources, the same key (and directory name)
    for name in KERNEL_MODULES:
        text = (copy / name).read_text()
        (copy / name).write_text(text + "\n# edited\n")
        edited = KernelCache(copy, KERNEL_MODULES, linkwork.__version__, parent=tmp_path / "c")
        assert edited.key != same.key, name
        assert edited.directory != same.directory
        (copy / name).write_text(text)
    assert (
        KernelCache(copy, KERNEL_MODULES, "9.9", parent=tmp_path / "c").key != same.key
    )  # linkwork's version


def test_the_marker_lists_compiled_groups_of_the_current_key_only(tmp_path: Path) -> None:
    toy = KernelCache(Path(kernel_cache.__file__).parent, ("version.py",), "1", parent=tmp_path)
    assert not toy.ready("tracing")
    toy.mark_ready(["tracing"])
    assert toy.ready("tracing") and not toy.ready("synthesis")
    toy.mark_ready(["synthesis"])
    content = json.loads(toy.marker.read_text())
    assert content["groups"] == ["synthesis", "tracing"] and content["key"] == toy.key
    content["key"] = "0" * 16  # a marker copied from other sources means nothing
    toy.marker.write_text(json.dumps(content))
    assert not toy.ready("tracing")


def test_a_kernel_outside_the_listed_modules_is_refused() -> None:
    def stray(x: float) -> float:
        return x

    with pytest.raises(RuntimeError, match="not in KERNEL_MODULES"):
        CACHE.kernel()(stray)


def test_the_cache_folder_can_be_chosen(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("LINKWORK_CACHE_DIR", str(tmp_path / "shared"))
    assert kernel_cache.default_parent(Path(linkwork.__file__).parent) == tmp_path / "shared"
    monkeypatch.delenv("LINKWORK_CACHE_DIR")
    assert CACHE.directory.name == f"kernels-{CACHE.key}"


def test_stale_directories_are_removed_only_from_the_package_folder(tmp_path: Path) -> None:
    root = tmp_path / "pkg"
    (root / "__pycache__" / "kernels-0000").mkdir(parents=True)
    (root / "version.py").write_text(textwrap.dedent("x = 1\n"))
    own = KernelCache(root, ("version.py",), "1", parent=root / "__pycache__")
    own.directory.mkdir()
    assert own.remove_stale() == [root / "__pycache__" / "kernels-0000"] and own.directory.exists()
    (tmp_path / "shared" / "kernels-1111").mkdir(parents=True)
    shared = KernelCache(root, ("version.py",), "1", parent=tmp_path / "shared")
    assert shared.remove_stale() == [] and (tmp_path / "shared" / "kernels-1111").exists()
